#include "core/diffusion/model_kind.h"

#include <array>

#include "core/diffusion/representation.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

struct Kind {
  const char* stage;
  const char* model;
  const char* representation;  // motion models only
  const char* condition;       // motion models only
  const char* name;
};

constexpr std::array<Kind, 6> kKinds{{
    {"contact.diffusion", "contact", "", "", "a contact model"},
    {"motion.diffusion", "motion", kKeypointsRepresentation, kContactCondition, "the method's motion model"},
    {"motion.diffusion_mano", "motion", kManoRepresentation, kContactCondition, "a MANO-Rep motion model"},
    {"motion.mdm_b", "motion", kManoRepresentation, kNoCondition, "an MDM-B model"},
    {"joints.omomo_b", "motion", kJointsRepresentation, kNoCondition, "an OMOMO-B joint model (stage one)"},
    {"motion.omomo_b", "motion", kManoRepresentation, kJointsCondition, "an OMOMO-B hand model (stage two)"},
}};

const Kind* kind_of(const ModelInfo& info) {
  for (const Kind& k : kKinds) {
    if (info.network.model != k.model) continue;
    if (info.network.model == "contact") return &k;
    if (info.representation == k.representation && info.condition == k.condition) return &k;
  }
  return nullptr;
}

std::string details(const std::string& model, const std::string& representation, const std::string& condition) {
  if (model == "contact") return "sampling contact maps";
  return "sampling " + describe_representation(representation) + ", conditioned on " + describe_condition(condition);
}

}  // namespace

std::string sampling_stage(const ModelInfo& info) {
  const Kind* k = kind_of(info);
  return k ? k->stage : "";
}

std::string describe_model(const ModelInfo& info) {
  const Kind* k = kind_of(info);
  const std::string d = details(info.network.model, info.representation, info.condition);
  return k ? std::string(k->name) + " (" + d + ")" : "a " + info.network.model + " model (" + d + ")";
}

void check_sampling_stage(const ModelInfo& info, const std::string& path, const std::string& stage) {
  const std::string mine = sampling_stage(info);
  if (mine == stage) return;
  std::string needs;
  for (const Kind& k : kKinds)
    if (stage == k.stage) needs = std::string(k.name) + " (" + details(k.model, k.representation, k.condition) + ")";
  throw Error(stage + " cannot sample " + path + ": it is " + describe_model(info) +
              (mine.empty() ? ", which no stage samples" : ", sampled by " + mine) +
              (needs.empty() ? "" : "; " + stage + " needs " + needs));
}

}  // namespace bimart::diffusion
