#include "core/diffusion/generation.h"

#include <ATen/ATen.h>
#include <torch/csrc/autograd/grad_mode.h>

#include <filesystem>
#include <map>
#include <mutex>

#include "core/data/normalization.h"
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
      schedule_(make_schedule(checkpoint_.info.schedule, checkpoint_.info.diffusion_steps)) {
  net_ = make_denoiser(checkpoint_, path_);
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

at::Tensor DiffusionModel::generate(const at::Tensor& O, const at::Tensor& G, const at::Tensor& C,
                                    const Guidance* guidance, const GenerateOptions& o, at::Generator gen) const {
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
  at::Tensor contact;
  if (motion && o.use_contact) {
    if (!C.defined()) throw Error(path_ + ": the motion model needs contact maps (or use_contact off)");
    contact = C.dim() == 3 ? C.unsqueeze(0).expand({S, N, 2, 1024}) : C;
    if (contact.dim() != 4 || contact.size(0) != S || contact.size(1) != N || contact.size(2) != 2 || contact.size(3) != 1024)
      throw Error("generate: contact maps must be [N, 2, 1024] or [" + std::to_string(S) + ", N, 2, 1024], got " +
                  c10::str(C.sizes()));
  }
  const int W = window();
  const int D = info.network.sample_size;
  const auto spans = windows(N, W, std::min(o.overlap, W - 1));
  at::Tensor result = at::zeros({S, N, D});
  at::Tensor weight = at::zeros({N});

  for (const auto& [start, length] : spans) {
    // Conditions of the window, padded to its length by repeating the last frame.
    at::Tensor o_w = O.slice(0, start, start + length).to(at::kFloat);
    at::Tensor g_w = G.slice(0, start, start + length).to(at::kFloat).clone();
    g_w.slice(1, 3, 6) -= g_w.slice(0, 0, 1).slice(1, 3, 6);
    const at::Tensor obj = st.normalize_object(o_w, g_w).unsqueeze(0).expand({S, length, kObjectConditionSize}).contiguous();
    at::Tensor cond_emb;
    if (!motion) {
      cond_emb = net_->encode_conditions(obj);
    } else {
      at::Tensor c_w;
      if (contact.defined()) c_w = st.normalize_c(contact.slice(1, start, start + length).to(at::kFloat)).flatten(-2);
      const at::Tensor with = contact.defined() ? net_->encode_conditions(obj, c_w) : net_->encode_conditions(obj);
      if (o.cfg_lambda != 0.0 && contact.defined()) {
        const at::Tensor without = net_->encode_conditions(obj);
        cond_emb = at::cat({with, without}, 0);
      } else {
        cond_emb = with;
      }
    }
    const bool cfg = cond_emb.size(0) == 2 * S;
    const auto predict = [&](const at::Tensor& x_t, int t) {
      const at::Tensor xin = cfg ? at::cat({x_t, x_t}, 0) : x_t;
      const at::Tensor steps = at::full({xin.size(0)}, t, at::kLong);
      const at::Tensor out = net_->forward(xin, steps, cond_emb);
      at::Tensor x0 = cfg ? out.slice(0, 0, S) : out;
      if (guidance != nullptr && motion) {
        const at::Tensor metres = st.denormalize_x(x0);
        const at::Tensor corr = guidance->correction(metres, start, t, schedule_.steps);
        x0 = st.normalize_x(metres + corr);
      }
      if (cfg) x0 = combine_cfg(x0, out.slice(0, S, 2 * S), o.cfg_lambda);
      return x0;
    };
    const at::Tensor noise = at::randn({S, length, D}, gen);
    const at::Tensor x = sample(schedule_, predict, noise, o.sampler, gen);
    // Cross-fade: weights ramp up over the overlap at the start of every window but the
    // first and down at the end of every window but the last.
    at::Tensor w = at::ones({length});
    const std::int64_t ov = std::min<std::int64_t>(o.overlap, length);
    if (start > 0 && ov > 0) w.slice(0, 0, ov).copy_(at::linspace(1.0 / (ov + 1), ov / (ov + 1.0), ov));
    if (start + length < N && ov > 0) w.slice(0, length - ov, length).mul_(at::linspace(ov / (ov + 1.0), 1.0 / (ov + 1), ov));
    result.slice(1, start, start + length) += x * w.view({1, length, 1});
    weight.slice(0, start, start + length) += w;
  }
  result /= weight.view({1, N, 1});
  if (!motion) return st.denormalize_c(result.view({S, N, 2, 1024})).clamp_min(0.0);
  return st.denormalize_x(result);
}

}  // namespace bimart::diffusion
