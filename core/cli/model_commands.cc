// bimart model check CHECKPOINT DATASET: how well a trained diffusion model denoises, on
// windows of a data set split with their ground-truth conditions (docs/training.md,
// "Checking a model"). Two measurements:
//  - one step: noise each window's sample to step t, predict x0 once, and report the
//    error per t (normalised MSE, and in metric units: mm per keypoint for the motion model,
//    mm per contact-map value for the contact model) next to the error of predicting the
//    data mean — a model that has learnt something beats the mean at every t;
//  - --sample: run the full sampler (as generation does) from noise with the ground-truth
//    conditions and report the sample's error and frame-to-frame smoothness against the
//    ground truth's — separates a weak denoiser from a sampling problem; --from T starts
//    from the truth noised to step T instead (SDEdit), which shows at which noise level
//    samples leave the data.
#include <fmt/format.h>

#include <iostream>

#include <ATen/ATen.h>
#include <torch/csrc/autograd/grad_mode.h>

#include "core/cli/command.h"
#include "core/data/normalization.h"
#include "core/data/window_dataset.h"
#include "core/diffusion/contact_guidance.h"
#include "core/diffusion/generation.h"
#include "core/diffusion/object_condition.h"
#include "core/diffusion/representation.h"
#include "core/diffusion/sampler.h"
#include "core/diffusion/schedule.h"
#include "core/diffusion/temporal_band.h"
#include "core/diffusion/training.h"
#include "core/features/contact_cue.h"
#include "core/util/error.h"

namespace bimart::cli {
namespace {

struct CheckArgs {
  std::string checkpoint, dataset, split = "train", sampler = "ddpm", expert;
  int windows = 16, steps = 0, from = -1, expert_from = 40, band = 0;
  long long seed = 1;
  double cfg = 0.5, guidance = 0;
  int place = 0;
  bool sample = false, no_contact = false;
};

// Mean over frames and points of the Euclidean error of 3-vectors: x, y [..., 3k].
double point_error(const at::Tensor& x, const at::Tensor& y) {
  return (x - y).view({-1, 3}).norm(2, 1).mean().item<double>();
}

// Mean keypoint acceleration ‖x_t − 2x_{t−1} + x_{t−2}‖ over frames and keypoints: X [B, T, 3k].
double acceleration(const at::Tensor& x) {
  const auto a = x.slice(1, 2) - 2 * x.slice(1, 1, -1) + x.slice(1, 0, -2);
  return a.reshape({-1, 3}).norm(2, 1).mean().item<double>();
}

int run_check(const CheckArgs& a) {
  c10::InferenceMode inference;
  const auto model = diffusion::DiffusionModel::load(a.checkpoint);
  const diffusion::ModelInfo& info = model->info();
  const bool motion = info.network.model == "motion";
  if (motion && info.representation != diffusion::kKeypointsRepresentation)
    throw Error("bimart model check measures keypoint errors; " + a.checkpoint + " samples " +
                diffusion::describe_representation(info.representation) + ", which it does not check");
  const NormalizationStats& st = info.normalization;
  WindowDatasetOptions dopt;
  dopt.variant = parse_bps_variant(info.variant);
  dopt.window = info.network.window;
  const WindowDataset data = WindowDataset::open(a.dataset, a.split, dopt);
  if (data.size() == 0) throw Error(a.dataset + ": no windows in the " + a.split + " split");

  const std::vector<std::int64_t> idx = data.spread(std::max(1, a.windows));  // fixed by the data set alone
  const int n = static_cast<int>(idx.size());
  const WindowBatch b = data.batch(idx);
  const at::Tensor obj = diffusion::model_object_condition(info.network, st, b.object_features, b.global_states);
  const at::Tensor truth = motion ? b.hand_features : b.contact_maps.flatten(-2);  // metres
  const at::Tensor x0 = diffusion::normalized_sample(info.network.model, info.representation, st, b);
  const auto to_metres = [&](const at::Tensor& z) {
    return motion ? st.denormalize_x(z) : st.contact_from_sample(z).flatten(-2);
  };
  const auto metric = [&](const at::Tensor& pred_m) {  // mm: keypoint distance (H) or |ΔC|
    if (motion) return 1000.0 * point_error(pred_m.slice(2, 0, 600), truth.slice(2, 0, 600));
    return 1000.0 * (pred_m - truth).abs().mean().item<double>();
  };

  diffusion::Denoiser net = model->network();
  const at::Tensor cond = motion && !a.no_contact
                              ? net->encode_conditions(obj, st.normalize_c(b.contact_maps).flatten(-2))
                              : net->encode_conditions(obj);
  const double mean_err = metric(to_metres(at::zeros_like(x0)));
  std::cout << fmt::format("{} model, {} windows of the {} split, {}\n", info.network.model, n, a.split,
                           motion ? (a.no_contact ? "null contact token" : "ground-truth contact maps")
                                  : "ground-truth object");
  std::cout << fmt::format("one step (x0 from x_t): mm = error of {}; predicting the data mean: {:.2f} mm\n",
                           motion ? "the 200 surface keypoints H" : "the contact maps", mean_err);
  // "swapped": each window's x_t built from another window's data, conditions kept; the
  // prediction's error against that other window's data. Near mse(norm): the network
  // follows x_t (the error is a reconstruction floor); near the data's variance: it ignores x_t.
  const at::Tensor other = x0.size(0) > 1 ? at::roll(x0, 1, 0) : x0;
  std::cout << fmt::format("   t   abar     mse(norm)  error mm   swapped (data variance {:.4f})\n",
                           x0.var().item<double>());
  at::Generator gen = at::detail::createCPUGenerator(static_cast<std::uint64_t>(a.seed));
  const auto& sched = model->schedule();
  for (int t : {0, 2, 5, 10, 15, 20, 25, 30, 35, 40, 45, 49}) {
    if (t >= sched.steps) continue;
    const at::Tensor noise = at::randn(x0.sizes(), gen);
    const at::Tensor tt = at::full({x0.size(0)}, t, at::kLong);
    const at::Tensor xt = diffusion::add_noise(sched, x0, noise, tt);
    const at::Tensor pred = diffusion::predict_x0(*net, sched, xt, tt, cond);
    const double mse = (pred - x0).pow(2).mean().item<double>();
    const at::Tensor swapped = diffusion::predict_x0(*net, sched, diffusion::add_noise(sched, other, noise, tt), tt, cond);
    std::cout << fmt::format("  {:2d}  {:.4f}  {:9.4f}  {:8.2f}  {:9.4f}\n", t, sched.alphas_cumprod[t], mse,
                             metric(to_metres(pred)), (swapped - other).pow(2).mean().item<double>());
  }
  if (!a.sample && a.from < 0) return 0;

  diffusion::GenerateOptions g;
  g.sampler.sampler = a.sampler;
  g.sampler.steps = a.steps;
  g.cfg_lambda = a.cfg;
  g.use_contact = !a.no_contact;
  g.band = a.band;
  // Guidance (and placement) towards window i's ground-truth maps; null when off.
  const auto guidance_for = [&](int i) -> std::unique_ptr<diffusion::ContactMapGuidance> {
    if (!motion || (a.guidance <= 0 && a.place <= 0)) return nullptr;
    auto g = std::make_unique<diffusion::ContactMapGuidance>(
        object_points_from_bps(b.object_features[i], data.basis_points(), b.global_states[i].select(1, 6), dopt.variant),
        b.contact_maps[i], a.guidance);
    g->set_placement(a.place);
    return g;
  };
  at::Tensor sm;  // [n, T, D] metres (contact maps flattened)
  if (a.from < 0 && a.expert.empty()) {
    std::vector<at::Tensor> outs;
    for (int i = 0; i < n; ++i) {
      const at::Tensor C = motion && !a.no_contact ? b.contact_maps[i] : at::Tensor();
      const auto guidance = guidance_for(i);
      outs.push_back(model->generate(b.object_features[i], b.global_states[i], C, guidance.get(), g, gen)[0]);
    }
    sm = motion ? at::stack(outs, 0) : at::stack(outs, 0).flatten(-2);
  } else {  // all windows in one batch: from noise, or from the truth noised to step `from`
    g.sampler.start = a.from;
    const bool cfg = motion && !a.no_contact && a.cfg != 0.0;
    const at::Tensor uncond = cfg ? net->encode_conditions(obj) : at::Tensor();
    // An expert for the noisiest steps (t >= expert_from): another checkpoint of the same model.
    diffusion::Denoiser expert{nullptr};
    at::Tensor e_cond, e_uncond;
    if (!a.expert.empty()) {
      const auto e = diffusion::DiffusionModel::load(a.expert);
      if (e->info().network.model != info.network.model || e->schedule().steps != sched.steps ||
          e->info().network.object_condition_size != info.network.object_condition_size)
        throw Error(a.expert + ": not a " + info.network.model + " model with the same schedule and object condition");
      expert = e->network();
      e_cond = motion && !a.no_contact ? expert->encode_conditions(obj, st.normalize_c(b.contact_maps).flatten(-2))
                                       : expert->encode_conditions(obj);
      if (cfg) e_uncond = expert->encode_conditions(obj);
    }
    // Guidance towards the ground-truth maps, one per window (each has its own object).
    std::vector<std::unique_ptr<diffusion::ContactMapGuidance>> guides;
    for (int i = 0; i < n; ++i)
      if (auto g = guidance_for(i)) guides.push_back(std::move(g));
    const std::int64_t frames = x0.size(1);
    const at::Tensor band = a.band > 0 && a.band < frames ? diffusion::band_projection(frames, a.band) : at::Tensor();
    // c (normalised) plus each window's guidance correction (one of the two kinds), in metres.
      const auto guided = [&](const at::Tensor& c, int t, GuidanceCorrection which) {
      const at::Tensor m = st.denormalize_x(c);
      std::vector<at::Tensor> corr;
      for (int i = 0; i < n; ++i) {
        corr.push_back(((*guides[i]).*which)(m.slice(0, i, i + 1), 0, t, sched.steps));
        if (!corr.back().defined()) return c;
      }
      return st.normalize_x(m + at::cat(corr, 0));
    };
    const auto predict = [&](const at::Tensor& x, int t) {
      const at::Tensor tt = at::full({x.size(0)}, t, at::kLong);
      const bool high = !expert.is_empty() && t >= a.expert_from;
      diffusion::DenoiserImpl& d = high ? *expert : *net;
      at::Tensor c = diffusion::predict_x0(d, sched, x, tt, high ? e_cond : cond);
      if (!guides.empty()) c = guided(c, t, &Guidance::correction);
      c = diffusion::band_limit(
          cfg ? diffusion::combine_cfg(c, diffusion::predict_x0(d, sched, x, tt, high ? e_uncond : uncond), a.cfg) : c,
          band);
      return guides.empty() ? c : guided(c, t, &Guidance::placement);  // placement after CFG, as in sampling
    };
    const at::Tensor start =
        a.from < 0 ? at::randn(x0.sizes(), gen)
                   : diffusion::add_noise(sched, x0, at::randn(x0.sizes(), gen), at::full({x0.size(0)}, a.from, at::kLong));
    sm = to_metres(diffusion::sample(sched, predict, start, g.sampler, gen));
  }
  if (a.band > 0)  // what the band costs the data itself
    std::cout << fmt::format("ground truth through the band (lowest {} DCT frequencies): error {:.2f} mm\n", a.band,
                             metric(to_metres(diffusion::band_limit(x0, a.band))));
  std::cout << fmt::format("sampled ({} {}{}{}{}): error {:.2f} mm\n", a.sampler, a.steps == 0 ? sched.steps : a.steps,
                           motion ? fmt::format(", CFG {}", a.cfg) : "", a.band > 0 ? fmt::format(", band {}", a.band) : "",
                           a.from < 0 ? "" : fmt::format(", from the truth noised to t = {}", a.from), metric(sm));
  if (motion) {
    // Placement vs shape: the error of each hand's keypoint centroid, and what is left
    // once both centroids are matched.
    const auto hands = [](const at::Tensor& x) { return x.slice(2, 0, 600).reshape({x.size(0), x.size(1), 2, 100, 3}); };
    const at::Tensor hs = hands(sm), ht = hands(truth);
    const at::Tensor cs = hs.mean(3, true), ct = ht.mean(3, true);
    std::cout << fmt::format("  hand centroid error {:.2f} mm; keypoints with the centroids matched {:.2f} mm\n",
                             1000.0 * (cs - ct).norm(2, -1).mean().item<double>(),
                             1000.0 * ((hs - cs) - (ht - ct)).norm(2, -1).mean().item<double>());
    // Hands touching the object (ground-truth contact map below 1 cm somewhere) vs apart.
    const at::Tensor touching = std::get<0>(b.contact_maps.min(-1)) < 0.01;  // [n, T, 2]
    const at::Tensor per_hand = (hs - ht).norm(2, -1).mean(-1);               // [n, T, 2]
    const auto share_mean = [&](const at::Tensor& m) {
      const double k = m.sum().item<double>();
      return k > 0 ? 1000.0 * (per_hand * m).sum().item<double>() / k : NAN;
    };
    std::cout << fmt::format("  hands touching the object ({:.0f} % of hand-frames): {:.2f} mm; apart: {:.2f} mm\n",
                             100.0 * touching.to(at::kDouble).mean().item<double>(), share_mean(touching.to(at::kFloat)),
                             share_mean((~touching).to(at::kFloat)));
    std::cout << fmt::format("  keypoint Accel (H): sample {:.3f} mm/frame², ground truth {:.3f}\n",
                             1000.0 * acceleration(sm.slice(2, 0, 600)), 1000.0 * acceleration(truth.slice(2, 0, 600)));
  } else {
    const auto change = [](const at::Tensor& c) { return (c.slice(1, 1) - c.slice(1, 0, -1)).abs().mean().item<double>(); };
    std::cout << fmt::format("  frame-to-frame change |C_t - C_t-1|: sample {:.3f} mm, ground truth {:.3f} mm\n",
                             1000.0 * change(sm), 1000.0 * change(truth));
    // Whether the maps put a hand on the object at all: a hand-frame touches when its map's
    // minimum is below 1 cm (what placement and the Con metric hinge on).
    const auto minima = [](const at::Tensor& c) { return std::get<0>(c.reshape({c.size(0), c.size(1), 2, -1}).min(-1)); };
    const at::Tensor ms = minima(sm), mt = minima(truth), touching = mt < 0.01;
    const double k = touching.sum().item<double>();
    std::cout << fmt::format("  hand-frames touching (min C < 1 cm): sample {:.1f} %, ground truth {:.1f} %; where the truth "
                             "touches, the sample's min C is {:.1f} mm (truth {:.1f})\n",
                             100.0 * (ms < 0.01).to(at::kDouble).mean().item<double>(),
                             100.0 * touching.to(at::kDouble).mean().item<double>(),
                             k > 0 ? 1000.0 * (ms * touching).sum().item<double>() / k : NAN,
                             k > 0 ? 1000.0 * (mt * touching).sum().item<double>() / k : NAN);
  }
  return 0;
}

}  // namespace

void add_model_commands(CLI::App& app, Commands& out) {
  auto* model = app.add_subcommand("model", "Inspect a trained diffusion model");
  model->require_subcommand(1);
  auto a = std::make_shared<CheckArgs>();
  auto* check = model->add_subcommand("check", "Denoising error per diffusion step on a data split (and of full samples)");
  check->add_option("checkpoint", a->checkpoint, "Model checkpoint (.npz)")->required();
  check->add_option("dataset", a->dataset, "Data set folder (bimart data synth)")->required();
  check->add_option("--split", a->split, "train or test")->capture_default_str();
  check->add_option("--windows", a->windows, "Windows, evenly spaced over the split")->capture_default_str();
  check->add_option("--seed", a->seed, "Noise seed")->capture_default_str();
  check->add_flag("--sample", a->sample, "Also sample every window from noise with its ground-truth conditions");
  check->add_option("--sampler", a->sampler, "ddpm or ddim (with --sample)")->capture_default_str();
  check->add_option("--steps", a->steps, "DDIM steps (0 = all)")->capture_default_str();
  check->add_option("--cfg", a->cfg, "Classifier-free guidance λ (motion model)")->capture_default_str();
  check->add_option("--from", a->from, "Sample from the truth noised to this step instead of from noise (-1 = off)")
      ->capture_default_str();
  check->add_option("--expert", a->expert, "Experimental: another checkpoint of the same model for the noisiest steps")
      ->check(CLI::ExistingFile);
  check->add_option("--expert-from", a->expert_from, "The expert takes the steps t >= this")->capture_default_str();
  check->add_option("--band", a->band, "Keep the lowest N DCT frequencies over time of every x0 prediction (0 = off)")
      ->capture_default_str();
  check->add_option("--guidance", a->guidance,
                    "Motion model, with --sample: contact-map guidance towards the ground-truth maps at this scale (0 = off)")
      ->capture_default_str();
  check->add_option("--place", a->place,
                    "Motion model, with --sample: translate each hand onto the ground-truth contacts at the last N steps "
                    "(contact placement; 0 = off)")
      ->capture_default_str();
  check->add_flag("--no-contact", a->no_contact, "Motion model: the null contact token instead of the maps");
  out.push_back({check, [a] { return run_check(*a); }, false});
}

}  // namespace bimart::cli
