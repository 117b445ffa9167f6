// What every output (glTF scene, viewer page, picture) is made from: one sequence file
// (docs/formats.md, "Sequence"), its object, and the two hand models that pose it.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "core/hand/hand_model.h"
#include "core/io/sequence.h"
#include "core/object/articulated_object.h"

namespace bimart {

struct SceneSource {
  std::string path;  // the sequence file ("" when built in memory)
  Sequence sequence;
  ArticulatedObject object;
  std::shared_ptr<const std::array<HandModel, 2>> hands;  // {left, right}
  std::array<const HandModel*, 2> models() const { return {&(*hands)[0], &(*hands)[1]}; }
};

// The hand models {left, right}: these files, or the shipped procedural hands when both are
// empty. Throws bimart::Error naming the file (missing, unreadable, wrong side).
std::shared_ptr<const std::array<HandModel, 2>> load_export_hands(const std::string& mano_left,
                                                                  const std::string& mano_right);

// Refuses hand models that do not fit the sequence: when the sequence stores posed vertices
// (`hand_vertices`), their count must be the model's and the models must reproduce them
// (within 1 mm at the first, middle and last frame). `where` names the sequence in errors.
void check_hands_fit(const Sequence& sequence, const std::array<const HandModel*, 2>& models,
                     const std::string& where);

// Reads the sequence file, its object and the models, and checks them; every error names
// the file and what is wrong.
SceneSource load_scene_source(const std::string& sequence_path,
                              std::shared_ptr<const std::array<HandModel, 2>> hands);

}  // namespace bimart
