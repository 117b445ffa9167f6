// A procedural laptop's "use" trajectory of a given length, encoded with NP-BPS: the
// conditions the generation tests sample for.
#pragma once

#include <ATen/core/Tensor.h>

#include <cstdint>

#include "core/features/bps.h"
#include "core/object/families/families.h"
#include "core/synth/trajectory.h"
#include "core/util/data_path.h"

namespace bimart::diffusion {

struct EncodedTrajectory {
  at::Tensor O, G;  // [frames, 1024, 3], [frames, 7]
  std::int64_t frames = 0;
};

inline EncodedTrajectory encoded_laptop_use(int frames) {
  const ArticulatedObject object = make_object("laptop", 3);
  TrajectoryOptions to;
  to.min_frames = to.max_frames = frames;
  const Trajectory tr = plan_trajectory(object, SequenceKind::Use, 11, to);
  const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(BpsVariant::PerPart)));
  const ObjectEncoding e = encode_object(object, tr.tensor(), basis, BpsVariant::PerPart);
  return EncodedTrajectory{e.features, e.global_states, tr.num_frames()};
}

}  // namespace bimart::diffusion
