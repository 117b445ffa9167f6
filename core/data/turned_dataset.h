// A data set with its objects turned about their hinge axes (issue 38, "any canonical
// frame"): each object's canonical frame turned by φ about the hinge (−z through the
// origin), its sequences' root rotations compensated, so every frame's world geometry —
// object and hands — is unchanged and only what the models see (the canonical frame) turns.
// The hinge angle keeps its meaning: a turn about z commutes with the hinge's.
#pragma once

#include <string>
#include <vector>

#include "core/object/articulated_object.h"
#include "core/object/object_state.h"

namespace bimart {

// The object with both parts turned by `radians` about the z axis.
ArticulatedObject turned_object(const ArticulatedObject& object, double radians);

// The state of the turned object that puts it where `state` put the original: R' = R·R_z(−φ).
ObjectState turned_state(const ObjectState& state, double radians);

struct TurnedDatasetSummary {
  int objects = 0, sequences = 0;
};

// Writes `out` (a data set folder: manifest.json, objects/, sequences/) with the sequences of
// `split` of the data set `folder` and their objects turned by each of `degrees`; the
// manifest lists them under the same split. One angle keeps every name (an evaluation set
// turned); several write one copy per angle, named with "_t<degrees>" (box_05_t90; 0 = the
// original), e.g. training data in several turns. Throws bimart::Error when `out` holds a
// data set already (unless `force`), for no or a non-finite angle, or when a sequence
// cannot be read.
TurnedDatasetSummary write_turned_dataset(const std::string& folder, const std::string& split,
                                          const std::vector<double>& degrees, const std::string& out,
                                          bool force = false);

}  // namespace bimart
