#include "core/diffusion/generation.h"

#include <ATen/ATen.h>
#include <torch/csrc/autograd/grad_mode.h>

#include <filesystem>
#include <map>
#include <mutex>

#include "core/data/normalization.h"
#include "core/diffusion/object_condition.h"
#include "core/diffusion/representation.h"
#include "core/diffusion/temporal_band.h"
#include "core/features/mano_representation.h"
#include "core/util/error.h"

namespace bimart::diffusion {

std::shared_ptr<const DiffusionModel> DiffusionModel::load(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, std::pair<std::filesystem::file_time_type, std::shared_ptr<const DiffusionModel>>> cache;
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(path, ec).string();
  const auto mtime = std::filesystem::last_write_time(path, ec);
  if (ec) throw Error("model checkpoint " + path + " does not exist (train one with bimart train, docs/training.md)");
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(canonical);
  if (it != cache.end() && it->second.first == mtime) return it->second.second;
  auto model = std::make_shared<const DiffusionModel>(load_checkpoint(path), path);
  cache[canonical] = {mtime, model};
  return model;
}

DiffusionModel::DiffusionModel(Checkpoint checkpoint, std::string path)
    : checkpoint_(std::move(checkpoint)), path_(std::move(path)),
      schedule_(make_schedule(checkpoint_.info.schedule, checkpoint_.info.diffusion_steps, checkpoint_.info.schedule_shift)) {
  net_ = make_denoiser(checkpoint_, path_);
  const ModelInfo& i = checkpoint_.info;
  if (i.network.model == "contact" && i.network.sample_size != i.normalization.contact_sample_size())
    throw Error(path_ + ": the contact model samples " + std::to_string(i.network.sample_size) +
                " numbers per frame, but its statistics' contact basis gives " +
                std::to_string(i.normalization.contact_sample_size()));
  if (i.network.model == "motion" && i.representation == kManoRepresentation && !i.normalization.mano_mean.defined())
    throw Error(path_ + ": a MANO-Rep motion model without MANO-Rep normalisation statistics");
}

std::vector<std::pair<std::int64_t, std::int64_t>> DiffusionModel::windows(std::int64_t frames, int window,
                                                                          int overlap) {
  if (overlap < 0 || overlap >= window)
    throw Error("window overlap must be in [0, " + std::to_string(window - 1) + "], got " + std::to_string(overlap));
  std::vector<std::pair<std::int64_t, std::int64_t>> w;
  if (frames <= window) return {{0, frames}};
  const std::int64_t hop = window - overlap;
  for (std::int64_t s = 0;; s += hop) {
    if (s + window >= frames) {
      w.push_back({frames - window, window});
      break;
    }
    w.push_back({s, window});
  }
  return w;
}

namespace {

// Blending weights of one window over its frames: 1 inside, a raised-cosine ramp over the
// frames it shares with the previous window (up) and with the next one (down); the two
// ramps multiply where they meet (overlaps longer than half a window).
at::Tensor window_weights(const std::vector<std::pair<std::int64_t, std::int64_t>>& spans, std::size_t k) {
  const auto [start, length] = spans[k];
  at::Tensor w = at::ones({length}, at::kDouble);
  const auto ramp = [](std::int64_t n) {  // n values rising in (0, 1)
    at::Tensor i = at::arange(n, at::kDouble).add_(0.5).mul_(M_PI / static_cast<double>(n));
    return i.cos().mul_(-0.5).add_(0.5);
  };
  if (k > 0) {
    const std::int64_t ov = spans[k - 1].first + spans[k - 1].second - start;
    if (ov > 0) w.slice(0, 0, ov).mul_(ramp(ov));
  }
  if (k + 1 < spans.size()) {
    const std::int64_t ov = start + length - spans[k + 1].first;
    if (ov > 0) w.slice(0, length - ov, length).mul_(ramp(ov).flip(0));
  }
  return w.to(at::kFloat);
}

// Windows of a sequence batched as [K * S, L, D] (window-major: row k * S + s is sample s of
// window k) and the sequence [S, N, D] they cover. Every denoising step fuses the windows'
// estimates into one sequence (a weighted mean where they overlap) and hands each window
// its part back, so neighbouring windows agree on their shared frames at every step
// (MultiDiffusion, Bar-Tal et al. 2023) and no seam is left to cross-fade at the end.
struct WindowLayout {
  std::vector<std::pair<std::int64_t, std::int64_t>> spans;
  std::int64_t frames = 0, samples = 0, length = 0;
  std::vector<at::Tensor> weights;  // [L] per window
  at::Tensor total;                 // [N]: sum of the weights covering each frame

  WindowLayout(std::vector<std::pair<std::int64_t, std::int64_t>> s, std::int64_t n, std::int64_t samples_)
      : spans(std::move(s)), frames(n), samples(samples_), length(spans.front().second) {
    total = at::zeros({n});
    for (std::size_t k = 0; k < spans.size(); ++k) {
      weights.push_back(window_weights(spans, k));
      total.slice(0, spans[k].first, spans[k].first + length) += weights.back();
    }
  }
  std::int64_t count() const { return static_cast<std::int64_t>(spans.size()); }

  at::Tensor fuse(const at::Tensor& windows) const {  // [K * S, L, D] -> [S, N, D]
    const std::int64_t D = windows.size(2);
    at::Tensor seq = at::zeros({samples, frames, D}, windows.options());
    const at::Tensor per = windows.view({count(), samples, length, D});
    for (std::int64_t k = 0; k < count(); ++k)
      seq.slice(1, spans[k].first, spans[k].first + length) += per[k] * weights[k].view({1, length, 1});
    return seq / total.view({1, frames, 1});
  }
  at::Tensor split(const at::Tensor& seq) const {  // [S, N, D] -> [K * S, L, D]
    std::vector<at::Tensor> parts;
    for (const auto& [start, len] : spans) parts.push_back(seq.slice(1, start, start + len));
    return at::cat(parts, 0).contiguous();
  }
  // A per-window tensor [K, L, ...] (conditions) repeated for every sample: [K * S, L, ...].
  at::Tensor per_sample(const at::Tensor& per_window) const {
    return per_window.repeat_interleave(samples, 0).contiguous();
  }
};

}  // namespace

at::Tensor DiffusionModel::generate(const at::Tensor& O, const at::Tensor& G, const at::Tensor& C,
                                    const Guidance* guidance, const GenerateOptions& o, at::Generator gen,
                                    const SampleConstraint* constraint) const {
  c10::InferenceMode inference;
  const ModelInfo& info = checkpoint_.info;
  const NormalizationStats& st = info.normalization;
  const bool motion = info.network.model == "motion";
  const std::int64_t N = O.size(0);
  const std::int64_t S = o.samples;
  if (S < 1 || S > 1024) throw Error("samples must be in [1, 1024], got " + std::to_string(S));
  if (O.dim() != 3 || O.size(1) != 1024 || O.size(2) != 3 || G.dim() != 2 || G.size(0) != N || G.size(1) != 7)
    throw Error("generate: need O [N, 1024, 3] and G [N, 7], got " + c10::str(O.sizes()) + " and " + c10::str(G.sizes()));
  if (N < 1) throw Error("generate: the trajectory has no frames");
  const bool mano = motion && info.representation == kManoRepresentation;
  const bool joints = motion && info.representation == kJointsRepresentation;
  if ((mano || joints) && guidance != nullptr)
    throw Error(path_ + ": guidance corrects keypoints X = [H | D], but this model samples " +
                describe_representation(info.representation) + ": run it without a guidance stage");
  if (mano && constraint != nullptr)
    throw Error(path_ + ": pinned hands are imposed on keypoints X = [H | D], but this model samples the MANO "
                "representation (MANO-Rep): use a keypoint motion model (motion.diffusion) to direct the hands");
  at::Tensor contact;
  if (motion && info.condition == kJointsCondition) {
    // OMOMO-B's second stage: the joints of both hands [N, 96] or [S, N, 96] (m, canonical).
    if (!C.defined()) throw Error(path_ + ": this model is conditioned on the joint positions of both hands; none given");
    contact = C.dim() == 2 ? C.unsqueeze(0).expand({S, N, C.size(-1)}) : C;
    if (contact.dim() != 3 || contact.size(0) != S || contact.size(1) != N || contact.size(2) != kManoRepJointsSize)
      throw Error("generate: joints must be [N, 96] or [" + std::to_string(S) + ", N, 96], got " + c10::str(C.sizes()));
  } else if (motion && info.condition == kContactCondition && o.use_contact) {
    if (!C.defined()) throw Error(path_ + ": the motion model needs contact maps (or use_contact off)");
    contact = C.dim() == 3 ? C.unsqueeze(0).expand({S, N, 2, 1024}) : C;
    if (contact.dim() != 4 || contact.size(0) != S || contact.size(1) != N || contact.size(2) != 2 || contact.size(3) != 1024)
      throw Error("generate: contact maps must be [N, 2, 1024] or [" + std::to_string(S) + ", N, 2, 1024], got " +
                  c10::str(C.sizes()));
  }
  const int W = window();
  const int D = info.network.sample_size;
  const WindowLayout lay(windows(N, W, std::min(o.overlap, W - 1)), N, S);
  const std::int64_t K = lay.count(), B = K * S;

  // Conditions of every window, encoded once: the object features and the global states
  // with each window's translation taken relative to its own first frame.
  std::vector<at::Tensor> objs;
  for (const auto& [start, length] : lay.spans) {
    const at::Tensor o_w = O.slice(0, start, start + length).to(at::kFloat);
    at::Tensor g_w = G.slice(0, start, start + length).to(at::kFloat).clone();
    g_w.slice(1, 3, 6) -= g_w.slice(0, 0, 1).slice(1, 3, 6);
    objs.push_back(model_object_condition(info.network, st, o_w, g_w));
  }
  const at::Tensor obj = lay.per_sample(at::stack(objs, 0));  // [B, L, 3079], or 3072 without G
  at::Tensor cond_emb;
  if (!motion) {
    cond_emb = net_->encode_conditions(obj);
  } else {
    at::Tensor c_w;
    if (contact.defined())
      c_w = lay.split(info.condition == kJointsCondition ? st.normalize_joints(contact.to(at::kFloat))
                                                         : st.normalize_c(contact.to(at::kFloat)).flatten(-2));
    const at::Tensor with = contact.defined() ? net_->encode_conditions(obj, c_w) : net_->encode_conditions(obj);
    cond_emb = o.cfg_lambda != 0.0 && contact.defined() ? at::cat({with, net_->encode_conditions(obj)}, 0) : with;
  }
  const bool cfg = cond_emb.size(0) == 2 * B;

  // The band's projection over a window's frames, built once (undefined: no band).
  at::Tensor band;
  if (o.band > 0 && o.band < lay.length) band = band_projection(lay.length, o.band);
  // Every window takes its part of the fused sequence (nothing to fuse for one window).
  const auto agree = [&](const at::Tensor& x) { return K == 1 ? x : lay.split(lay.fuse(x)); };
  // x0 (normalised) plus one of the guidance's corrections, window by window, in metres;
  // an undefined correction (placement off) leaves x0 as it is.
  const auto guide = [&](const at::Tensor& x0, int t, GuidanceCorrection which) {
    const at::Tensor metres = st.denormalize_x(x0);
    std::vector<at::Tensor> corr;
    for (std::int64_t k = 0; k < K; ++k) {
      corr.push_back((guidance->*which)(metres.slice(0, k * S, (k + 1) * S), lay.spans[k].first, t, schedule_.steps));
      if (!corr.back().defined()) return x0;
    }
    return st.normalize_x(metres + at::cat(corr, 0));
  };
  // The constraint imposed on x0 (normalised) window by window, in the model's units.
  const auto to_units = [&](const at::Tensor& w) {
    if (!motion) return st.contact_from_sample(w).flatten(-2);
    return joints ? st.denormalize_joints(w) : st.denormalize_x(w);
  };
  const auto from_units = [&](const at::Tensor& u) {
    if (!motion) return st.contact_sample(u.unflatten(-1, {2, 1024}));
    return joints ? st.normalize_joints(u) : st.normalize_x(u);
  };
  const auto constrain = [&](const at::Tensor& x0, int t) {
    std::vector<at::Tensor> parts;
    for (std::int64_t k = 0; k < K; ++k) {
      const at::Tensor fixed =
          constraint->impose(to_units(x0.slice(0, k * S, (k + 1) * S)), lay.spans[k].first, t, schedule_.steps);
      parts.push_back(from_units(fixed));
    }
    return at::cat(parts, 0).to(x0.scalar_type());
  };
  const auto predict = [&](const at::Tensor& x_t, int t) {
    const at::Tensor xin = cfg ? at::cat({x_t, x_t}, 0) : x_t;
    const at::Tensor out = predict_x0(*net_, schedule_, xin, at::full({xin.size(0)}, t, at::kLong), cond_emb);
    at::Tensor x0 = cfg ? out.slice(0, 0, B) : out;
    if (guidance != nullptr && motion) x0 = guide(x0, t, &Guidance::correction);
    if (cfg) x0 = combine_cfg(x0, out.slice(0, B, 2 * B), o.cfg_lambda);
    x0 = band_limit(x0, band);
    if (guidance != nullptr && motion) x0 = guide(x0, t, &Guidance::placement);
    if (constraint != nullptr) x0 = constrain(x0, t);
    return agree(x0);
  };
  // One noise per sequence frame, so shared frames start equal; fused again after every step.
  const at::Tensor noise = lay.split(at::randn({S, N, D}, gen));
  const StepHook hook = [&](int, int, at::Tensor& x) { x = agree(x); };
  const at::Tensor result = lay.fuse(sample(schedule_, predict, noise, o.sampler, gen, hook));
  if (mano) return st.denormalize_mano(result);
  at::Tensor out = joints   ? st.denormalize_joints(result)
                   : motion ? st.denormalize_x(result)
                            : st.contact_from_sample(result).clamp_min(0.0);
  if (constraint == nullptr) return out;
  // Exactly on the result too (the contact basis cannot hold every imposed value).
  const at::Tensor flat = motion ? out : out.flatten(-2);
  const at::Tensor fixed = constraint->impose(flat, 0, -1, schedule_.steps);
  return motion ? fixed : fixed.unflatten(-1, {2, 1024});
}

}  // namespace bimart::diffusion
