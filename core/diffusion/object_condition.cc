#include "core/diffusion/object_condition.h"

#include "core/data/normalization.h"
#include "core/util/error.h"

namespace bimart::diffusion {

int object_condition_size(bool global_states) {
  return kObjectFeatureSize + (global_states ? kGlobalStateSize : 0);
}

bool reads_global_states(const DenoiserConfig& network) {
  if (network.object_condition_size == object_condition_size(true)) return true;
  if (network.object_condition_size == object_condition_size(false)) return false;
  throw Error("a " + network.model + " model with an object condition of " +
              std::to_string(network.object_condition_size) + " per frame: expected " +
              std::to_string(object_condition_size(true)) + " ([O | G]) or " +
              std::to_string(object_condition_size(false)) + " (O, without G)");
}

std::string global_states_name(bool global_states) { return global_states ? "with G" : "without G"; }

at::Tensor model_object_condition(const DenoiserConfig& network, const NormalizationStats& stats,
                                  const at::Tensor& object_features, const at::Tensor& global_states) {
  const at::Tensor condition = stats.normalize_object(object_features, global_states);
  return reads_global_states(network) ? condition : condition.narrow(-1, 0, kObjectFeatureSize).contiguous();
}

}  // namespace bimart::diffusion
