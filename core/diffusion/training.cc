#include "core/diffusion/training.h"

#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/adam.h>

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <set>
#include <sstream>

#include "core/data/manifest.h"
#include "core/data/normalization.h"
#include "core/data/window_dataset.h"
#include "core/diffusion/checkpoint.h"
#include "core/diffusion/distributed.h"
#include "core/diffusion/object_condition.h"
#include "core/diffusion/representation.h"
#include "core/features/mano_representation.h"
#include "core/diffusion/schedule.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/progress.h"
#include "core/util/text.h"

namespace fs = std::filesystem;

namespace bimart::diffusion {
namespace {

// ---- configuration ----

std::string where(const std::string& file, const YAML::Node& n) {
  return file + ":" + std::to_string(n.Mark().line + 1);
}

void check_keys(const std::string& file, const YAML::Node& map, const std::string& section,
                const std::set<std::string>& known) {
  if (!map.IsMap()) throw Error(where(file, map) + ": '" + section + "' must be a mapping");
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    if (known.count(key)) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    throw Error(where(file, kv.first) + ": unknown key '" + key + "' in " + section + " (known: " + list + ")");
  }
}

template <class T>
void read(const std::string& file, const YAML::Node& map, const char* key, T& out) {
  const YAML::Node n = map[key];
  if (!n) return;
  try {
    out = n.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(where(file, n) + ": '" + key + "' has a value of the wrong type");
  }
}

void set_sizes(DenoiserConfig& n, const std::string& model, int contact_basis, bool global_states,
               const std::string& representation, const std::string& condition) {
  n.model = model;
  n.sample_size = model != "contact" ? motion_sample_size(representation)
                  : contact_basis > 0 ? 2 * contact_basis : 2 * kBasisRows;
  n.object_condition_size = object_condition_size(global_states);
  n.contact_condition_size = model == "contact" ? 0 : condition_size(condition);
}

// ---- helpers ----

std::uint64_t mix(std::uint64_t a, std::uint64_t b) {  // splitmix64 of a combined word
  std::uint64_t z = a + 0x9e3779b97f4a7c15ULL * (b + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Every random draw of a step comes from a seed of (config seed, step, rank): an
// interrupted run resumes with identical batches, noise and dropout, and no random state
// needs storing. The windows come from `data_rng`, noise, steps and contact dropout from
// the returned generator, the network's dropout from libtorch's default generator (seeded
// here too; one training per process).
at::Generator seed_step(std::uint64_t seed, std::int64_t step, int rank, std::mt19937_64& data_rng) {
  const std::uint64_t s = mix(mix(seed, static_cast<std::uint64_t>(step)), static_cast<std::uint64_t>(rank));
  data_rng.seed(s);
  {
    auto def = at::detail::getDefaultCPUGenerator();
    std::lock_guard<std::mutex> lock(def.mutex());
    def.set_current_seed(mix(s, 17));
  }
  return at::detail::createCPUGenerator(mix(s, 29));
}

std::string adam_key(const at::Tensor& p) { return c10::guts::to_string(p.unsafeGetTensorImpl()); }

// torch::optim::Adam keeps its per-parameter state under the address of the parameter's
// TensorImpl (torch/csrc/api/src/optim/adam.cpp); these two move it to and from names.
void save_adam(torch::optim::Adam& opt, torch::nn::Module& net, TrainState& st) {
  for (const auto& p : net.named_parameters()) {
    auto it = opt.state().find(adam_key(p.value()));
    if (it == opt.state().end()) continue;
    const auto& s = static_cast<const torch::optim::AdamParamState&>(*it->second);
    st.adam_exp_avg[p.key()] = s.exp_avg().detach().clone();
    st.adam_exp_avg_sq[p.key()] = s.exp_avg_sq().detach().clone();
    st.adam_step = s.step();
  }
}

void restore_adam(torch::optim::Adam& opt, torch::nn::Module& net, const TrainState& st, const std::string& what) {
  for (const auto& p : net.named_parameters()) {
    const auto m = st.adam_exp_avg.find(p.key());
    const auto v = st.adam_exp_avg_sq.find(p.key());
    if (m == st.adam_exp_avg.end() || v == st.adam_exp_avg_sq.end()) {
      if (st.adam_step == 0) continue;
      throw Error(what + ": no optimizer state for '" + p.key() + "'");
    }
    if (!m->second.sizes().equals(p.value().sizes()) || !v->second.sizes().equals(p.value().sizes()))
      throw Error(what + ": optimizer state for '" + p.key() + "' has the wrong shape");
    auto s = std::make_unique<torch::optim::AdamParamState>();
    s->step(st.adam_step);
    s->exp_avg(m->second.clone());
    s->exp_avg_sq(v->second.clone());
    opt.state()[adam_key(p.value())] = std::move(s);
  }
}

struct LossRow {
  std::int64_t step;
  double lr, loss, validation, windows_per_second, seconds;
};

std::vector<LossRow> read_loss_log(const std::string& path, std::int64_t up_to_step) {
  std::vector<LossRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream s(line);
    LossRow r{};
    char c;
    std::string val;
    if (!(s >> r.step >> c >> r.lr >> c >> r.loss >> c)) continue;
    std::getline(s, val, ',');
    r.validation = val.empty() ? NAN : std::stod(val);
    s >> r.windows_per_second >> c >> r.seconds;
    if (r.step <= up_to_step) rows.push_back(r);
  }
  return rows;
}

void write_loss_log(const std::string& path, const std::vector<LossRow>& rows) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "step,lr,loss,validation,windows_per_second,seconds\n";
    char buf[256];
    for (const auto& r : rows) {
      std::string v;
      if (std::isfinite(r.validation)) {
        std::snprintf(buf, sizeof buf, "%.6f", r.validation);
        v = buf;
      }
      std::snprintf(buf, sizeof buf, "%lld,%.6g,%.6f,%s,%.2f,%.1f\n", static_cast<long long>(r.step), r.lr, r.loss,
                    v.c_str(), r.windows_per_second, r.seconds);
      out << buf;
    }
  });
}

}  // namespace

// ---- configuration ----

TrainConfig load_train_config(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw Error("cannot read the training config " + path);
  } catch (const YAML::Exception& e) {
    throw Error(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  TrainConfig c;
  c.file = path;
  {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    c.text = s.str();
  }
  check_keys(path, root, "the training config",
             {"model", "data", "out", "export", "export_half", "init", "variant", "representation", "condition", "stride", "network",
              "diffusion", "training"});
  read(path, root, "model", c.model);
  if (c.model != "contact" && c.model != "motion")
    throw Error(where(path, root["model"] ? root["model"] : root) + ": 'model' must be contact or motion");
  c.network = DenoiserConfig::paper(c.model);
  read(path, root, "data", c.data);
  read(path, root, "out", c.out);
  read(path, root, "export", c.export_path);
  read(path, root, "export_half", c.export_half);
  read(path, root, "init", c.init);
  read(path, root, "variant", c.variant);
  read(path, root, "representation", c.representation);
  if (c.representation != kKeypointsRepresentation && c.representation != kManoRepresentation &&
      c.representation != kJointsRepresentation)
    throw Error(where(path, root["representation"]) + ": 'representation' must be keypoints, mano or joints, got '" +
                c.representation + "'");
  if (c.representation != kKeypointsRepresentation && c.model != "motion")
    throw Error(where(path, root["representation"]) + ": 'representation: " + c.representation +
                "' is for the motion model only; the contact model samples contact maps");
  read(path, root, "condition", c.condition);
  if (c.condition != kContactCondition && c.condition != kNoCondition && c.condition != kJointsCondition)
    throw Error(where(path, root["condition"]) + ": 'condition' must be contact, none or joints, got '" + c.condition + "'");
  if (c.condition != kContactCondition && c.model != "motion")
    throw Error(where(path, root["condition"]) + ": 'condition' is for the motion model only");
  read(path, root, "stride", c.stride);
  if (const YAML::Node n = root["network"]) {
    check_keys(path, n, "network",
               {"latent", "layers", "heads", "feedforward", "condition_hidden", "dropout", "output", "skip_rank",
                "contact_cue", "contact_points", "point_hidden", "contact_log_eps",
                "contact_basis", "global_states"});
    read(path, n, "latent", c.network.latent);
    read(path, n, "layers", c.network.layers);
    read(path, n, "heads", c.network.heads);
    read(path, n, "feedforward", c.network.feedforward);
    read(path, n, "condition_hidden", c.network.condition_hidden);
    read(path, n, "dropout", c.network.dropout);
    read(path, n, "output", c.network.output);
    read(path, n, "skip_rank", c.network.skip_rank);
    read(path, n, "contact_cue", c.network.contact_cue);
    read(path, n, "contact_points", c.network.contact_points);
    read(path, n, "point_hidden", c.network.point_hidden);
    read(path, n, "contact_log_eps", c.contact_log_eps);
    read(path, n, "contact_basis", c.contact_basis);
    read(path, n, "global_states", c.global_states);
  }
  if (const YAML::Node n = root["diffusion"]) {
    check_keys(path, n, "diffusion", {"schedule", "steps", "shift"});
    read(path, n, "schedule", c.schedule);
    read(path, n, "shift", c.schedule_shift);
    read(path, n, "steps", c.diffusion_steps);
  }
  if (const YAML::Node n = root["training"]) {
    check_keys(path, n, "training",
               {"batch", "steps", "lr", "warmup", "weight_decay", "grad_clip", "ema", "contact_dropout", "noisy_share", "noisy_from", "seed",
                "checkpoint_every", "validate_every", "validation_windows", "log_every"});
    read(path, n, "batch", c.batch);
    read(path, n, "steps", c.steps);
    read(path, n, "lr", c.lr);
    read(path, n, "warmup", c.warmup);
    read(path, n, "weight_decay", c.weight_decay);
    read(path, n, "grad_clip", c.grad_clip);
    read(path, n, "ema", c.ema);
    read(path, n, "contact_dropout", c.contact_dropout);
    read(path, n, "noisy_share", c.noisy_share);
    read(path, n, "noisy_from", c.noisy_from);
    read(path, n, "seed", c.seed);
    read(path, n, "checkpoint_every", c.checkpoint_every);
    read(path, n, "validate_every", c.validate_every);
    read(path, n, "validation_windows", c.validation_windows);
    read(path, n, "log_every", c.log_every);
  }
  set_sizes(c.network, c.model, c.contact_basis, c.global_states, c.representation, c.condition);
  try {
    validate(c);
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  return c;
}

void validate(const TrainConfig& c) {
  const auto need = [](bool ok, const std::string& msg) {
    if (!ok) throw Error(msg);
  };
  need(c.model == "contact" || c.model == "motion", "'model' must be contact or motion");
  need(!c.data.empty(), "'data' (the data set folder) is required");
  need(!c.out.empty(), "'out' (the run folder) is required");
  parse_bps_variant(c.variant);
  check_representation_name(c.representation);
  need(c.representation == kKeypointsRepresentation || c.model == "motion",
       "'representation: " + c.representation + "' is for the motion model only; the contact model samples contact maps");
  check_condition_name(c.condition);
  need(c.condition == kContactCondition || c.model == "motion", "'condition' is for the motion model only");
  need(!(c.condition == kJointsCondition && c.representation == kJointsRepresentation),
       "a model that samples the joints cannot be conditioned on them ('condition: joints' with 'representation: joints')");
  if (c.model == "motion")
    need(c.network.contact_condition_size == condition_size(c.condition),
         "the motion model's second condition must be " + std::to_string(condition_size(c.condition)) +
             " wide for condition " + c.condition + ", got " + std::to_string(c.network.contact_condition_size));
  if (c.model == "motion")
    need(c.network.sample_size == motion_sample_size(c.representation),
         "the motion model's sample size must be " + std::to_string(motion_sample_size(c.representation)) +
             " for representation " + c.representation + ", got " + std::to_string(c.network.sample_size));
  need(c.stride >= 1, "'stride' must be positive");
  need(c.contact_log_eps >= 0 && std::isfinite(c.contact_log_eps), "'network.contact_log_eps' must be >= 0 (metres)");
  need(c.contact_log_eps == 0 || c.model == "contact", "'network.contact_log_eps' is for the contact model only");
  need(c.contact_basis >= 0 && c.contact_basis <= kBasisRows, "'network.contact_basis' must be 0 (off) to 1024");
  need(c.contact_basis == 0 || c.model == "contact", "'network.contact_basis' is for the contact model only");
  if (c.model == "contact")
    need(c.network.sample_size == (c.contact_basis > 0 ? 2 * c.contact_basis : 2 * kBasisRows),
         "the contact model's sample size must be 2 x 'network.contact_basis' (or 2048 without a basis)");
  need(c.network.object_condition_size == object_condition_size(c.global_states),
       "the object condition must be " + std::to_string(object_condition_size(c.global_states)) + " wide " +
           global_states_name(c.global_states) + " ('network.global_states'), got " +
           std::to_string(c.network.object_condition_size));
  c.network.validate();
  make_schedule(c.schedule, c.diffusion_steps, c.schedule_shift);
  need(c.batch >= 1 && c.batch <= 100000, "'training.batch' must be in [1, 100000]");
  need(c.steps >= 1, "'training.steps' must be positive");
  need(c.lr > 0 && c.lr < 1, "'training.lr' must be in (0, 1)");
  need(c.warmup >= 0, "'training.warmup' must not be negative");
  need(c.weight_decay >= 0, "'training.weight_decay' must not be negative");
  need(c.grad_clip >= 0, "'training.grad_clip' must not be negative");
  need(c.ema >= 0 && c.ema < 1, "'training.ema' must be in [0, 1)");
  need(c.contact_dropout >= 0 && c.contact_dropout <= 1, "'training.contact_dropout' must be in [0, 1]");
  need(c.noisy_share >= 0 && c.noisy_share <= 1, "'training.noisy_share' must be in [0, 1]");
  need(c.noisy_from >= 0 && c.noisy_from < c.diffusion_steps,
       "'training.noisy_from' must be in [0, diffusion.steps), got " + std::to_string(c.noisy_from));
  need(c.checkpoint_every >= 1, "'training.checkpoint_every' must be positive");
  need(c.validate_every >= 0, "'training.validate_every' must not be negative");
  need(c.validation_windows >= 1, "'training.validation_windows' must be positive");
  need(c.log_every >= 1, "'training.log_every' must be positive");
}

double learning_rate(const TrainConfig& c, std::int64_t step) {
  if (c.warmup > 0 && step < c.warmup) return c.lr * static_cast<double>(step + 1) / c.warmup;
  const double span = std::max<double>(1.0, static_cast<double>(c.steps - c.warmup));
  const double progress = std::min(1.0, static_cast<double>(step - c.warmup) / span);
  return c.lr * 0.5 * (1.0 + std::cos(M_PI * progress));
}

// ---- one step ----

at::Tensor normalized_sample(const std::string& model, const std::string& representation,
                             const NormalizationStats& stats, const WindowBatch& b) {
  if (model == "contact") return stats.contact_sample(b.contact_maps);
  if (representation == kKeypointsRepresentation) return stats.normalize_x(b.hand_features);
  if (!b.mano.defined())
    throw Error("the batch holds no MANO representation (open the data set with WindowDatasetOptions::mano)");
  if (representation == kJointsRepresentation) return stats.normalize_joints(mano_representation_joints(b.mano));
  return stats.normalize_mano(b.mano);
}

at::Tensor normalized_condition(const std::string& model, const std::string& condition, const NormalizationStats& stats,
                                const WindowBatch& b) {
  if (model != "motion" || condition == kNoCondition) return {};
  if (condition == kContactCondition) return stats.normalize_c(b.contact_maps).flatten(-2);
  if (!b.mano.defined())
    throw Error("the batch holds no MANO representation (open the data set with WindowDatasetOptions::mano)");
  return stats.normalize_joints(mano_representation_joints(b.mano));
}

StepInputs make_step_inputs(const TrainConfig& c, const NormalizationStats& stats, const WindowBatch& b,
                            at::Generator gen) {
  StepInputs in;
  const auto B = b.mask.size(0);
  in.object = model_object_condition(c.network, stats, b.object_features, b.global_states);
  in.sample = normalized_sample(c.model, c.representation, stats, b);
  in.contact = normalized_condition(c.model, c.condition, stats, b);
  if (in.contact.defined()) in.use_contact = at::rand({B}, gen) >= c.contact_dropout;
  in.mask = b.mask;
  in.noise = at::randn(in.sample.sizes(), gen);
  in.t = at::randint(0, c.diffusion_steps, {B}, gen, at::kLong);
  if (c.noisy_share > 0) {  // drawn only then, so that uniform runs keep their random stream
    const at::Tensor noisy = at::randint(c.noisy_from, c.diffusion_steps, {B}, gen, at::kLong);
    in.t = at::where(at::rand({B}, gen) < c.noisy_share, noisy, in.t);
  }
  return in;
}

LossParts step_loss(Denoiser& net, const NoiseSchedule& schedule, const StepInputs& in) {
  const at::Tensor x_t = add_noise(schedule, in.sample, in.noise, in.t);
  const at::Tensor cond = net->encode_conditions(in.object, in.contact, in.use_contact);
  const at::Tensor pred = predict_x0(*net, schedule, x_t, in.t, cond);
  const at::Tensor err = (pred - in.sample).pow(2).mean(-1);  // [B, T]
  LossParts lp;
  lp.sum = (err * in.mask).sum();
  lp.frames = in.mask.sum().item<double>();
  return lp;
}

// The Gaussian skip's directions (DenoiserConfig::output) from the normalised samples of up
// to 1024 windows spread evenly over the train split (deterministic).
static std::pair<at::Tensor, at::Tensor> fit_gaussian_skip(const TrainConfig& c, const NormalizationStats& stats,
                                                    const WindowDataset& data) {
  const std::vector<std::int64_t> idx = data.spread(1024);
  std::vector<at::Tensor> rows;
  for (std::size_t first = 0; first < idx.size(); first += 128) {
    const auto last = idx.begin() + static_cast<std::ptrdiff_t>(std::min(idx.size(), first + 128));
    rows.push_back(normalized_sample(c.model, c.representation, stats, data.batch({idx.begin() + static_cast<std::ptrdiff_t>(first), last})));
  }
  const at::Tensor all = at::cat(rows, 0);  // [n, W, D]; padding repeats the last frame
  auto fit = principal_directions(all.reshape({-1, all.size(-1)}), c.network.skip_rank);
  if (c.network.output == "temporal") {  // variance per (DCT frequency, direction)
    const at::Tensor z = at::matmul(dct_matrix(all.size(1)), at::matmul(all, fit.first));  // [n, W, k]
    fit.second = z.pow(2).mean(0).contiguous();
  }
  // The DCT is orthonormal, so the temporal variances sum to the directions' variances × W.
  log::info("Gaussian skip ({}): the top {} directions hold {:.4f} of the normalised samples' variance", c.network.output,
            fit.first.size(1), fit.second.sum().item<double>() / static_cast<double>(c.network.sample_size) /
                (c.network.output == "temporal" ? static_cast<double>(all.size(1)) : 1.0));
  return fit;
}

StepInputs draw_step(const TrainConfig& config, const NormalizationStats& stats, const WindowDataset& data,
                     std::int64_t step, int rank) {
  std::mt19937_64 rng;
  at::Generator gen = seed_step(config.seed, step, rank, rng);
  return make_step_inputs(config, stats, data.sample_batch(config.batch, rng), gen);
}

int warm_start(torch::nn::Module& net, const std::map<std::string, at::Tensor>& weights) {
  torch::NoGradGuard ng;
  int copied = 0;
  for (auto& p : net.named_parameters()) {
    const auto it = weights.find(p.key());
    if (it == weights.end()) continue;
    const at::Tensor& from = it->second;
    at::Tensor to = p.value();
    if (from.sizes().equals(to.sizes())) {
      to.copy_(from);
    } else if (from.dim() == 2 && to.dim() == 2 && from.size(0) == to.size(0) && from.size(1) < to.size(1)) {
      to.slice(1, 0, from.size(1)).copy_(from);  // the old inputs; the new ones start at zero
      to.slice(1, from.size(1)).zero_();
    } else {
      log::warn("init: '{}' is {} here and {} in the initial model: left at random", p.key(),
                c10::str(to.sizes()), c10::str(from.sizes()));
      continue;
    }
    ++copied;
  }
  return copied;
}

// ---- the loop ----

TrainResult train(const TrainConfig& config, const TrainOptions& options) {
  validate(config);
  DataParallel* dp = options.parallel.get();
  const int rank = dp ? dp->rank() : 0;
  const int world = dp ? dp->world_size() : 1;
  const bool root = rank == 0;
  const bool show = options.progress && root;
  const auto t_start = std::chrono::steady_clock::now();

  const fs::path out(config.out);
  const std::string checkpoint_path = (out / "checkpoint.npz").string();
  const std::string log_path = (out / "loss.csv").string();
  if (root) {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec) throw Error("cannot create the run folder " + config.out + ": " + ec.message());
  }

  // Data.
  WindowDatasetOptions wo;
  wo.variant = parse_bps_variant(config.variant);
  wo.stride = config.stride;
  wo.mano = config.representation != kKeypointsRepresentation || config.condition == kJointsCondition;
  std::unique_ptr<ProgressBar> bar;
  wo.progress = [&](std::size_t done, std::size_t total) {
    if (!bar) bar = std::make_unique<ProgressBar>("features", total, show);
    bar->step();
    (void)done;
  };
  const WindowDataset train_set = WindowDataset::open(config.data, "train", wo);
  bar.reset();
  std::unique_ptr<WindowDataset> test_set;
  if (config.validate_every > 0 && root)
    test_set = std::make_unique<WindowDataset>(WindowDataset::open(config.data, "test", wo));
  bar.reset();
  if (train_set.size() == 0) throw Error(config.data + ": the train split has no windows");
  NormalizationStats stats = compute_normalization(train_set, kNormalizationStdFloor, config.contact_log_eps);
  if (config.contact_basis > 0) stats.c_basis = contact_basis(train_set, stats, config.contact_basis);
  const NoiseSchedule schedule = make_schedule(config.schedule, config.diffusion_steps, config.schedule_shift);

  ModelInfo info;
  info.network = config.network;
  info.schedule = config.schedule;
  info.diffusion_steps = config.diffusion_steps;
  info.schedule_shift = config.schedule_shift;
  info.variant = config.variant;
  info.representation = config.representation;
  info.condition = config.condition;
  info.basis_points = train_set.basis_points();
  info.keypoints = posing_keypoint_ids();
  info.normalization = stats;
  info.config_text = config.text;
  info.data_fingerprint = dataset_fingerprint(config.data);

  // Networks: the trained one and its EMA copy (used for validation and sampling).
  // Initialisation draws from libtorch's global generator: one training at a time seeds
  // and builds, so trainings sharing a process (ranks on threads) start alike.
  static std::mutex init_mutex;
  std::unique_lock<std::mutex> init_lock(init_mutex);
  torch::manual_seed(config.seed);
  Denoiser net(config.network);
  Denoiser ema_net(config.network);
  if (!config.init.empty() && !options.resume) {
    const Checkpoint ck = load_checkpoint(config.init);
    check_compatible(ck.info, config.init, config.model, config.variant, info.basis_points, info.keypoints,
                     config.representation);
    const int copied = warm_start(*net, ck.weights);
    if (show) log::info("initialised {} of {} parameters from {}", copied, net->named_parameters().size(), config.init);
  }
  load_state(*ema_net, state_of(*net), "EMA copy");
  if (config.network.output != "x0") {
    const auto [directions, variances] = fit_gaussian_skip(config, stats, train_set);
    net->set_gaussian_skip(directions, variances);
    ema_net->set_gaussian_skip(directions, variances);
  }
  if (net->reads_object_points()) {
    const bool scaled = parse_bps_variant(config.variant) != BpsVariant::Uniform;
    for (Denoiser* n : {&net, &ema_net})
      (*n)->set_cue_frame(stats.obj_mean.to(at::kFloat), stats.obj_std.to(at::kFloat), stats.c_mean.to(at::kFloat),
                          stats.c_std.to(at::kFloat), info.basis_points, scaled);
  }
  init_lock.unlock();
  ema_net->eval();
  torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(config.lr).weight_decay(config.weight_decay));

  std::int64_t step = 0;
  double best_validation = NAN;
  std::vector<LossRow> rows;
  if (options.resume) {
    if (!fs::exists(checkpoint_path))
      throw Error("--resume: no checkpoint " + checkpoint_path + " to resume from");
    const Checkpoint ck = load_checkpoint(checkpoint_path);
    if (!ck.train) throw Error(checkpoint_path + " holds no training state (an exported model?)");
    check_compatible(ck.info, checkpoint_path, config.model, config.variant, info.basis_points, info.keypoints,
                     config.representation);
    if (ck.info.network.describe() != config.network.describe())
      throw Error(checkpoint_path + ": the network differs from the config (" + ck.info.network.describe() +
                  " vs " + config.network.describe() + ")");
    // The noise schedule and the contact basis define what the network learns: a resume
    // must not change them silently.
    const auto schedule_text = [](const ModelInfo& m) {
      return m.schedule + ", " + std::to_string(m.diffusion_steps) + " steps, shift " + fmt::format("{:g}", m.schedule_shift);
    };
    if (schedule_text(ck.info) != schedule_text(info))
      throw Error(checkpoint_path + ": the diffusion schedule differs from the config (" + schedule_text(ck.info) +
                  " vs " + schedule_text(info) + ")");
    if (ck.info.network.object_condition_size != info.network.object_condition_size)
      throw Error(checkpoint_path + ": the checkpoint's model reads " + std::to_string(ck.info.network.object_condition_size) +
                  " object numbers per frame, the config " + std::to_string(info.network.object_condition_size) +
                  " ('network.global_states')");
    if (ck.info.network.sample_size != info.network.sample_size)
      throw Error(checkpoint_path + ": the contact basis differs from the config (sample size " +
                  std::to_string(ck.info.network.sample_size) + " vs " + std::to_string(info.network.sample_size) + ")");
    if (ck.info.data_fingerprint != info.data_fingerprint)
      log::warn("{}: the training data changed since this run started (fingerprint {} vs {})", checkpoint_path,
                ck.info.data_fingerprint, info.data_fingerprint);
    load_state(*net, ck.train->weights, checkpoint_path);
    load_state(*ema_net, ck.weights, checkpoint_path);
    restore_adam(opt, *net, *ck.train, checkpoint_path);
    step = ck.train->step;
    best_validation = ck.train->best_validation;
    if (root) rows = read_loss_log(log_path, step);
    if (show) log::info("resuming {} at step {} of {}", checkpoint_path, step, config.steps);
  }
  if (dp) {
    // Same start on every process, whatever each one read.
    std::vector<at::Tensor> all;
    for (auto& p : net->parameters()) all.push_back(p);
    for (auto& p : ema_net->parameters()) all.push_back(p);
    torch::NoGradGuard ng;
    dp->broadcast(all);
  }
  if (show)
    log::info("training {} ({} parameters) on {} windows of {} ({} processes), batch {}", config.network.describe(),
              net->num_parameters(), train_set.size(), config.data, world, config.batch);

  const auto write_checkpoint = [&]() {
    Checkpoint ck;
    ck.info = info;
    ck.weights = state_of(*ema_net);
    TrainState st;
    st.step = step;
    st.weights = state_of(*net);
    save_adam(opt, *net, st);
    st.best_validation = best_validation;
    ck.train = std::move(st);
    save_checkpoint(ck, checkpoint_path);
    if (!config.export_path.empty()) {
      Checkpoint release;
      release.info = info;
      release.weights = ck.weights;
      if (config.export_half)
        for (const auto& p : ema_net->named_parameters()) release.weights[p.key()] = p.value().detach().to(at::kHalf);
      save_checkpoint(release, config.export_path);
    }
    write_loss_log(log_path, rows);
  };

  const auto validation_loss = [&]() {
    torch::NoGradGuard ng;
    const std::vector<std::int64_t> idx = test_set->spread(config.validation_windows);
    double sum = 0, frames = 0;
    constexpr std::size_t kChunk = 32;
    for (std::size_t first = 0, chunk = 0; first < idx.size(); first += kChunk, ++chunk) {
      const WindowBatch b = test_set->batch({idx.begin() + static_cast<std::ptrdiff_t>(first),
                                             idx.begin() + static_cast<std::ptrdiff_t>(std::min(idx.size(), first + kChunk))});
      auto gen = at::detail::createCPUGenerator(static_cast<std::uint64_t>(1000003 + chunk));
      StepInputs in;
      in.object = model_object_condition(config.network, stats, b.object_features, b.global_states);
      in.sample = normalized_sample(config.model, config.representation, stats, b);
      in.contact = normalized_condition(config.model, config.condition, stats, b);
      in.mask = b.mask;
      in.noise = at::randn(in.sample.sizes(), gen);
      in.t = at::randint(0, config.diffusion_steps, {in.sample.size(0)}, gen, at::kLong);
      const LossParts lp = step_loss(ema_net, schedule, in);
      sum += lp.sum.item<double>();
      frames += lp.frames;
    }
    return frames > 0 ? sum / frames : NAN;
  };

  TrainResult result;
  double interval_loss = 0;
  int interval_steps = 0;
  std::int64_t windows_this_call = 0;
  std::int64_t steps_this_call = 0;
  auto t_interval = std::chrono::steady_clock::now();
  std::int64_t windows_interval = 0;
  const auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  const double seconds_before = rows.empty() ? 0.0 : rows.back().seconds;

  while (step < config.steps) {
    bool stop = options.stop_requested && options.stop_requested();
    if (options.stop_after > 0 && steps_this_call >= options.stop_after) stop = true;
    if (dp) stop = dp->all_reduce_sum(stop ? 1.0 : 0.0) > 0;
    if (stop) {
      result.interrupted = options.stop_requested && options.stop_requested();
      break;
    }
    const StepInputs in = draw_step(config, stats, train_set, step, rank);
    net->train();
    const LossParts lp = step_loss(net, schedule, in);
    const double frames = dp ? dp->all_reduce_sum(lp.frames) : lp.frames;
    const at::Tensor loss = lp.sum / std::max(frames, 1.0);
    opt.zero_grad();
    loss.backward();
    std::vector<at::Tensor> grads;
    for (auto& p : net->parameters()) {
      if (!p.grad().defined()) p.mutable_grad() = at::zeros_like(p);
      grads.push_back(p.grad());
    }
    if (dp) dp->all_reduce_sum(grads);
    if (config.grad_clip > 0) torch::nn::utils::clip_grad_norm_(net->parameters(), config.grad_clip);
    const double lr = learning_rate(config, step);
    for (auto& g : opt.param_groups()) static_cast<torch::optim::AdamOptions&>(g.options()).lr(lr);
    opt.step();
    {
      torch::NoGradGuard ng;
      const double d = std::min(config.ema, (1.0 + step) / (10.0 + step));
      auto ema_params = ema_net->parameters();
      auto params = net->parameters();
      for (std::size_t i = 0; i < params.size(); ++i) ema_params[i].mul_(d).add_(params[i], 1.0 - d);
    }
    ++step;
    ++steps_this_call;
    if (root) report_progress("train", static_cast<std::size_t>(step), static_cast<std::size_t>(config.steps));
    const double loss_all = dp ? dp->all_reduce_sum(lp.sum.item<double>()) / std::max(frames, 1.0) : loss.item<double>();
    interval_loss += loss_all;
    ++interval_steps;
    windows_interval += static_cast<std::int64_t>(config.batch) * world;
    windows_this_call += static_cast<std::int64_t>(config.batch) * world;

    const bool log_now = step % config.log_every == 0 || step == config.steps;
    const bool validate_now = test_set && config.validate_every > 0 && (step % config.validate_every == 0 || step == config.steps);
    if (root && (log_now || validate_now)) {
      const double rate = windows_interval / std::max(since(t_interval), 1e-9);
      LossRow r{step, lr, interval_loss / std::max(interval_steps, 1), NAN, rate,
                seconds_before + since(t_start)};
      if (validate_now) {
        r.validation = validation_loss();
        if (!(best_validation <= r.validation)) best_validation = r.validation;
      }
      rows.push_back(r);
      result.last_loss = r.loss;
      if (show) {
        const double eta = (config.steps - step) * config.batch * world / std::max(rate, 1e-9);
        std::string v = std::isfinite(r.validation) ? fmt::format("  validation {:.4f}", r.validation) : "";
        log::info("step {}/{}  loss {:.4f}{}  lr {:.2e}  {:.1f} windows/s  {} left", step, config.steps, r.loss, v, lr,
                  rate, format_duration(eta));
      }
      interval_loss = 0;
      interval_steps = 0;
      windows_interval = 0;
      t_interval = std::chrono::steady_clock::now();
    }
    if (root && (step % config.checkpoint_every == 0 || step == config.steps)) write_checkpoint();
  }
  if (root && steps_this_call > 0 && step % config.checkpoint_every != 0 && step != config.steps) write_checkpoint();
  // Nothing trained: write what is missing (a finished run resumed rewrites a deleted export,
  // e.g. to store it with export_half).
  if (root && steps_this_call == 0 &&
      (!fs::exists(checkpoint_path) || (!config.export_path.empty() && !fs::exists(config.export_path))))
    write_checkpoint();

  result.steps_done = step;
  result.finished = step >= config.steps;
  result.seconds = since(t_start);
  result.windows_per_second = windows_this_call / std::max(result.seconds, 1e-9);
  result.last_validation = best_validation;
  for (auto it = rows.rbegin(); it != rows.rend(); ++it)
    if (std::isfinite(it->validation)) {
      result.last_validation = it->validation;
      break;
    }
  result.checkpoint = checkpoint_path;
  if (options.final_weights != nullptr) *options.final_weights = state_of(*net);
  if (dp) dp->barrier();
  return result;
}

}  // namespace bimart::diffusion
