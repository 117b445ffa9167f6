#include "core/diffusion/checkpoint.h"

#include <ATen/ATen.h>
#include <torch/nn/module.h>

#include <cmath>

#include "core/diffusion/object_condition.h"
#include "core/diffusion/representation.h"
#include "core/hand/hand_model.h"
#include "core/hand/keypoints.h"
#include "core/io/npz.h"
#include "core/metrics/hand_vertices.h"
#include "core/io/npz_tensor.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

void set_string(NpzFile& f, const std::string& key, const std::string& value) {
  f.set(key, make_npy_strings({value}, {}));
}
std::string get_string(const NpzFile& f, const std::string& key) {
  const auto v = as_strings(f.get(key), f.where(key));
  if (v.size() != 1) throw Error(f.where(key) + " must hold one string");
  return v[0];
}
std::int64_t get_int(const NpzFile& f, const std::string& key) {
  const auto v = f.vector<std::int64_t>(key);
  if (v.size() != 1) throw Error(f.where(key) + " must hold one number");
  return v[0];
}
double get_double(const NpzFile& f, const std::string& key) {
  const auto v = f.vector<double>(key);
  if (v.size() != 1) throw Error(f.where(key) + " must hold one number");
  return v[0];
}

void store_map(NpzFile& f, const std::string& prefix, const TensorMap& m) {
  for (const auto& [name, t] : m) f.set(prefix + name, npy_from_tensor(t));
}
TensorMap read_map(const NpzFile& f, const std::string& prefix) {
  TensorMap m;
  for (const auto& key : f.keys())
    if (key.rfind(prefix, 0) == 0) {
      const at::Tensor t = tensor_from_npy(f.get(key), f.where(key));
      // Weights stored as float16 (TrainConfig::export_half) are widened: the network runs in float32.
      m[key.substr(prefix.size())] = t.scalar_type() == at::kHalf ? t.to(at::kFloat) : t;
    }
  return m;
}

// Network fields stored as integers (and dropout as a float).
struct IntField {
  const char* key;
  int DenoiserConfig::*member;
};
constexpr IntField kIntFields[] = {
    {"sample_size", &DenoiserConfig::sample_size},
    {"object_condition_size", &DenoiserConfig::object_condition_size},  // 3079 = [O | G], 3072 = O (w/o G)
    {"contact_condition_size", &DenoiserConfig::contact_condition_size},
    {"window", &DenoiserConfig::window},
    {"latent", &DenoiserConfig::latent},
    {"layers", &DenoiserConfig::layers},
    {"heads", &DenoiserConfig::heads},
    {"feedforward", &DenoiserConfig::feedforward},
    {"condition_hidden", &DenoiserConfig::condition_hidden},
};
// Fields added later: optional on load (older files keep the defaults).
constexpr IntField kLaterIntFields[] = {
    {"contact_points", &DenoiserConfig::contact_points},
    {"point_hidden", &DenoiserConfig::point_hidden},
};

}  // namespace

void save_checkpoint(const Checkpoint& c, const std::string& path) {
  NpzFile f;
  set_string(f, "format", kCheckpointFormat);
  f.set("version", make_npy_scalar<std::int64_t>(kCheckpointVersion));
  const ModelInfo& i = c.info;
  set_string(f, "network/model", i.network.model);
  for (const auto& field : kIntFields)
    f.set(std::string("network/") + field.key, make_npy_scalar<std::int64_t>(i.network.*field.member));
  f.set("network/dropout", make_npy_scalar<double>(i.network.dropout));
  set_string(f, "network/output", i.network.output);
  f.set("network/skip_rank", make_npy_scalar<std::int64_t>(i.network.skip_rank));
  f.set("network/contact_cue", make_npy_scalar<std::int64_t>(i.network.contact_cue ? 1 : 0));
  for (const auto& field : kLaterIntFields)
    f.set(std::string("network/") + field.key, make_npy_scalar<std::int64_t>(i.network.*field.member));
  // Spelled out beside object_condition_size (which decides it); files without it read G.
  f.set("network/global_states", make_npy_scalar<std::int64_t>(reads_global_states(i.network) ? 1 : 0));
  set_string(f, "diffusion/schedule", i.schedule);
  f.set("diffusion/steps", make_npy_scalar<std::int64_t>(i.diffusion_steps));
  if (i.schedule_shift != 1.0) f.set("diffusion/shift", make_npy_scalar<double>(i.schedule_shift));
  set_string(f, "encoder/variant", i.variant);
  set_string(f, "representation", i.representation);
  set_string(f, "condition", i.condition);
  if (!i.basis_points.defined()) throw Error(path + ": checkpoint without basis points");
  f.set("encoder/basis_points", npy_from_tensor(i.basis_points.to(at::kFloat)));
  f.set("hand/keypoints", make_npy(i.keypoints));
  store_normalization(i.normalization, f, "normalization/");
  set_string(f, "config", i.config_text);
  set_string(f, "data_fingerprint", i.data_fingerprint);
  store_map(f, "weights/", c.weights);
  if (c.train) {
    const TrainState& t = *c.train;
    f.set("train/step", make_npy_scalar<std::int64_t>(t.step));
    f.set("train/adam_step", make_npy_scalar<std::int64_t>(t.adam_step));
    f.set("train/best_validation", make_npy_scalar<double>(t.best_validation));
    store_map(f, "train/weights/", t.weights);
    store_map(f, "train/adam_exp_avg/", t.adam_exp_avg);
    store_map(f, "train/adam_exp_avg_sq/", t.adam_exp_avg_sq);
  }
  // Stored, not deflated: float weights barely compress, and storing is 10x faster.
  f.write(path, NpzCompression::Store);
}

Checkpoint load_checkpoint(const std::string& path) {
  const NpzFile f = NpzFile::read(path);
  if (!f.contains("format") || get_string(f, "format") != kCheckpointFormat)
    throw Error(path + ": not a bimart model checkpoint (no 'format' entry '" + std::string(kCheckpointFormat) + "')");
  const std::int64_t version = get_int(f, "version");
  if (version > kCheckpointVersion)
    throw Error(path + ": checkpoint version " + std::to_string(version) + " is newer than this program reads (" +
                std::to_string(kCheckpointVersion) + ")");
  Checkpoint c;
  ModelInfo& i = c.info;
  i.network.model = get_string(f, "network/model");
  const auto read_field = [&](const IntField& field) {
    const std::string key = std::string("network/") + field.key;
    const std::int64_t v = get_int(f, key);
    if (v < 0 || v > (1 << 24)) throw Error(f.where(key) + ": out of range");
    i.network.*field.member = static_cast<int>(v);
  };
  for (const auto& field : kIntFields) read_field(field);
  i.network.dropout = get_double(f, "network/dropout");
  // Checkpoints from before the skip output predicted x0 directly.
  i.network.output = f.contains("network/output") ? get_string(f, "network/output") : "x0";
  if (f.contains("network/skip_rank")) {
    const std::int64_t k = get_int(f, "network/skip_rank");
    if (k < 1 || k > 65536) throw Error(f.where("network/skip_rank") + ": out of range");
    i.network.skip_rank = static_cast<int>(k);
  }
  // Checkpoints from before the contact cue have none.
  i.network.contact_cue = f.contains("network/contact_cue") && get_int(f, "network/contact_cue") != 0;
  // ... and from before the contact points none.
  for (const auto& field : kLaterIntFields)
    if (f.contains(std::string("network/") + field.key)) read_field(field);
  try {
    i.network.validate();
    // Older files have no network/global_states: their object condition (3079) says "with G".
    const bool g = reads_global_states(i.network);
    if (f.contains("network/global_states") && (get_int(f, "network/global_states") != 0) != g)
      throw Error("network/global_states disagrees with an object condition of " +
                  std::to_string(i.network.object_condition_size));
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  i.schedule = get_string(f, "diffusion/schedule");
  i.diffusion_steps = static_cast<int>(get_int(f, "diffusion/steps"));
  if (f.contains("diffusion/shift")) i.schedule_shift = f.vector<double>("diffusion/shift").at(0);
  i.variant = get_string(f, "encoder/variant");
  // Checkpoints from before MANO-Rep sample keypoints.
  i.representation = f.contains("representation") ? get_string(f, "representation") : kKeypointsRepresentation;
  try {
    check_representation_name(i.representation);
    if (i.network.model == "motion" && i.network.sample_size != motion_sample_size(i.representation))
      throw Error("representation " + i.representation + " samples " + std::to_string(motion_sample_size(i.representation)) +
                  " numbers per frame, the network " + std::to_string(i.network.sample_size));
  } catch (const Error& e) {
    throw Error(f.where("representation") + ": " + e.what());
  }
  // Checkpoints from before the baselines are conditioned on C (motion) or nothing (contact).
  i.condition = f.contains("condition") ? get_string(f, "condition") : kContactCondition;
  try {
    check_condition_name(i.condition);
    if (i.network.model == "motion" && i.network.contact_condition_size != condition_size(i.condition))
      throw Error("condition " + i.condition + " is " + std::to_string(condition_size(i.condition)) +
                  " numbers per frame, the network's " + std::to_string(i.network.contact_condition_size));
  } catch (const Error& e) {
    throw Error(f.where("condition") + ": " + e.what());
  }
  i.basis_points = tensor_from_npy(f.get("encoder/basis_points", {-1, 3}), f.where("encoder/basis_points"));
  i.keypoints = f.vector<std::int64_t>("hand/keypoints");
  i.normalization = read_normalization(f, "normalization/");
  i.config_text = get_string(f, "config");
  i.data_fingerprint = get_string(f, "data_fingerprint");
  c.weights = read_map(f, "weights/");
  if (c.weights.empty()) throw Error(path + ": checkpoint holds no weights");
  if (f.contains("train/step")) {
    TrainState t;
    t.step = get_int(f, "train/step");
    t.adam_step = get_int(f, "train/adam_step");
    t.best_validation = get_double(f, "train/best_validation");
    t.weights = read_map(f, "train/weights/");
    t.adam_exp_avg = read_map(f, "train/adam_exp_avg/");
    t.adam_exp_avg_sq = read_map(f, "train/adam_exp_avg_sq/");
    c.train = std::move(t);
  }
  return c;
}

TensorMap state_of(const torch::nn::Module& module) {
  TensorMap m;
  for (const auto& p : module.named_parameters()) m[p.key()] = p.value().detach().clone();
  for (const auto& b : module.named_buffers()) m[b.key()] = b.value().detach().clone();
  return m;
}

void load_state(torch::nn::Module& module, const TensorMap& weights, const std::string& what) {
  torch::NoGradGuard no_grad;
  std::size_t used = 0;
  const auto copy = [&](const std::string& name, at::Tensor& target) {
    const auto it = weights.find(name);
    if (it == weights.end()) throw Error(what + ": no weights for '" + name + "'");
    if (!it->second.sizes().equals(target.sizes()))
      throw Error(what + ": weights '" + name + "' have shape " + c10::str(it->second.sizes()) +
                  ", the network expects " + c10::str(target.sizes()));
    target.copy_(it->second);
    ++used;
  };
  for (auto& p : module.named_parameters()) copy(p.key(), p.value());
  for (auto& b : module.named_buffers()) copy(b.key(), b.value());
  if (used != weights.size()) {
    for (const auto& [name, t] : weights) {
      const bool known = module.named_parameters().contains(name) || module.named_buffers().contains(name);
      if (!known) throw Error(what + ": unexpected weights '" + name + "' (another network?)");
    }
  }
}

std::vector<std::int64_t> posing_keypoint_ids() {
  const std::vector<int> ids = model_keypoints(load_hand_model(posing_hand_model_files()[0]));
  return std::vector<std::int64_t>(ids.begin(), ids.end());
}

Denoiser make_denoiser(const Checkpoint& checkpoint, const std::string& what) {
  Denoiser net(checkpoint.info.network);
  load_state(*net, checkpoint.weights, what);
  net->eval();
  return net;
}

void check_compatible(const ModelInfo& info, const std::string& what, const std::string& model,
                      const std::string& variant, const at::Tensor& basis_points,
                      const std::vector<std::int64_t>& keypoints, const std::string& representation) {
  std::vector<std::string> differs;
  if (!model.empty() && info.network.model != model)
    differs.push_back("it is a " + info.network.model + " model, not a " + model + " model");
  if (!representation.empty() && info.representation != representation)
    differs.push_back("hand representation: the model samples " + describe_representation(info.representation) +
                      ", this run needs " + describe_representation(representation));
  if (!variant.empty() && info.variant != variant)
    differs.push_back("encoder variant: trained with " + info.variant + ", run with " + variant);
  if (basis_points.defined()) {
    if (!basis_points.sizes().equals(info.basis_points.sizes())) {
      differs.push_back("basis points: trained with " + c10::str(info.basis_points.sizes()) + ", run with " +
                        c10::str(basis_points.sizes()));
    } else {
      const double d = (basis_points.to(at::kDouble) - info.basis_points.to(at::kDouble)).abs().max().item<double>();
      if (!(d <= 1e-6))
        differs.push_back("basis points: differ by up to " + std::to_string(d) +
                          " from the basis the model was trained with");
    }
  }
  if (!keypoints.empty() && keypoints != info.keypoints) {
    std::size_t first = 0;
    while (first < keypoints.size() && first < info.keypoints.size() && keypoints[first] == info.keypoints[first])
      ++first;
    differs.push_back("hand keypoints: " + std::to_string(keypoints.size()) + " ids, the model has " +
                      std::to_string(info.keypoints.size()) + "; first difference at index " + std::to_string(first));
  }
  if (differs.empty()) return;
  std::string msg = what + " does not fit this run:";
  for (const auto& d : differs) msg += "\n  - " + d;
  throw Error(msg);
}

}  // namespace bimart::diffusion
