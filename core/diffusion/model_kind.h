// Which stage samples a checkpoint: the kind of model its network, representation and
// condition make it (core/diffusion/representation.h), so that every sampling stage refuses
// another stage's model naming both — a baseline's model given to the method's stage, or
// the other way round.
//   contact model                                   contact.diffusion
//   motion, keypoints, conditioned on C             motion.diffusion       (the method)
//   motion, mano, conditioned on C                  motion.diffusion_mano  (MANO-Rep)
//   motion, mano, conditioned on nothing            motion.mdm_b           (MDM-B)
//   motion, joints, conditioned on nothing          joints.omomo_b         (OMOMO-B, stage one)
//   motion, mano, conditioned on the joints         motion.omomo_b          (OMOMO-B, stage two)
#pragma once

#include <string>

#include "core/diffusion/checkpoint.h"

namespace bimart::diffusion {

// The stage id that samples this model, or "" when no stage does.
std::string sampling_stage(const ModelInfo& info);
// "the MDM-B model (MANO-Rep, conditioned on nothing but the object)": for messages.
std::string describe_model(const ModelInfo& info);
// Throws bimart::Error unless `stage` samples the model at `path`, naming the model, the
// stage that samples it and what `stage` needs.
void check_sampling_stage(const ModelInfo& info, const std::string& path, const std::string& stage);

}  // namespace bimart::diffusion
