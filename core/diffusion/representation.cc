#include "core/diffusion/representation.h"

#include "core/features/hand_features.h"
#include "core/features/mano_representation.h"
#include "core/util/error.h"

namespace bimart::diffusion {

void check_representation_name(const std::string& name) {
  if (name != kKeypointsRepresentation && name != kManoRepresentation)
    throw Error("unknown hand representation '" + name + "' (known: keypoints, mano)");
}

int motion_sample_size(const std::string& representation) {
  check_representation_name(representation);
  return representation == kManoRepresentation ? kManoRepSize : kHandFeatureSize;
}

std::string describe_representation(const std::string& representation) {
  return representation == kManoRepresentation ? "mano (MANO-Rep)" : representation + " (X = [H | D])";
}

}  // namespace bimart::diffusion
