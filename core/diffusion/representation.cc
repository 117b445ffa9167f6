#include "core/diffusion/representation.h"

#include "core/features/hand_features.h"
#include "core/features/mano_representation.h"
#include "core/util/error.h"

namespace bimart::diffusion {

void check_representation_name(const std::string& name) {
  if (name != kKeypointsRepresentation && name != kManoRepresentation && name != kJointsRepresentation)
    throw Error("unknown hand representation '" + name + "' (known: keypoints, mano, joints)");
}

int motion_sample_size(const std::string& representation) {
  check_representation_name(representation);
  if (representation == kManoRepresentation) return kManoRepSize;
  if (representation == kJointsRepresentation) return kManoRepJointsSize;
  return kHandFeatureSize;
}

std::string describe_representation(const std::string& representation) {
  if (representation == kManoRepresentation) return "mano (MANO-Rep)";
  if (representation == kJointsRepresentation) return "joints (both hands' 16 joint positions)";
  return representation + " (X = [H | D])";
}

void check_condition_name(const std::string& name) {
  if (name != kContactCondition && name != kNoCondition && name != kJointsCondition)
    throw Error("unknown motion condition '" + name + "' (known: contact, none, joints)");
}

int condition_size(const std::string& condition) {
  check_condition_name(condition);
  if (condition == kContactCondition) return 2 * 1024;
  return condition == kJointsCondition ? kManoRepJointsSize : 0;
}

std::string describe_condition(const std::string& condition) {
  if (condition == kContactCondition) return "the contact maps C";
  if (condition == kJointsCondition) return "the joint positions of both hands";
  return "nothing but the object";
}

}  // namespace bimart::diffusion
