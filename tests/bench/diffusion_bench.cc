// Diffusion models on the CPU: training throughput (windows/s) per network size, sampling
// one 64-frame window (contact + motion with CFG and contact-map guidance, 50 DDPM steps or
// 10 DDIM steps; 1 or 10 samples), the same window directed (docs/directing.md), and one
// guidance step. Random weights: speed only.
// Run: bimart_benchmarks --benchmark_filter=Diffusion   (docs/performance.md, "Diffusion")
#include <benchmark/benchmark.h>

#include <torch/optim/adam.h>

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include "core/diffusion/checkpoint.h"
#include "core/diffusion/contact_guidance.h"
#include "core/diffusion/generation.h"
#include "core/diffusion/schedule.h"
#include "core/directing/contact_rules.h"
#include "core/directing/hand_pins.h"
#include "core/geometry/rotation.h"
#include "bench_object.h"
#include "tests/synth/shipped_hands.h"
#include "core/runtime/blas.h"

namespace bimart::diffusion {
namespace {

// Sizes tried: latent, layers, feed-forward, condition MLP width.
DenoiserConfig sized(const std::string& model, int which) {
  DenoiserConfig c = DenoiserConfig::paper(model);
  const int table[4][4] = {{128, 4, 256, 256}, {256, 4, 512, 256}, {384, 6, 768, 384}, {512, 8, 1024, 1024}};
  c.latent = table[which][0];
  c.layers = table[which][1];
  c.feedforward = table[which][2];
  c.condition_hidden = table[which][3];
  return c;
}
const char* size_name(int which) {
  static const char* names[] = {"tiny", "small", "medium", "paper"};
  return names[which];
}

void BM_DiffusionTrainStep(benchmark::State& state) {
  runtime::set_threads(static_cast<int>(state.range(2)));
  const std::string model = state.range(1) == 0 ? "contact" : "motion";
  torch::manual_seed(0);
  Denoiser net(sized(model, static_cast<int>(state.range(0))));
  torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(1e-4));
  const NoiseSchedule s = make_schedule("squaredcos_cap_v2", 50);
  const int B = 32;
  const int S = net->config().sample_size;
  const at::Tensor x0 = at::randn({B, 64, S}), obj = at::randn({B, 64, 3079});
  const at::Tensor contact = model == "motion" ? at::randn({B, 64, 2048}) : at::Tensor();
  const at::Tensor use = model == "motion" ? at::rand({B}) >= 0.5 : at::Tensor();
  for (auto _ : state) {
    const at::Tensor t = at::randint(0, 50, {B}, at::kLong);
    const at::Tensor xt = add_noise(s, x0, at::randn_like(x0), t);
    const at::Tensor loss = (net->forward(xt, t, net->encode_conditions(obj, contact, use)) - x0).pow(2).mean();
    opt.zero_grad();
    loss.backward();
    opt.step();
  }
  state.SetItemsProcessed(state.iterations() * B);
  state.SetLabel(std::string(size_name(static_cast<int>(state.range(0)))) + " " + model + ", " +
                 std::to_string(net->num_parameters()) + " parameters");
}
BENCHMARK(BM_DiffusionTrainStep)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}, {2}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0)
    ->UseRealTime();

NormalizationStats unit_stats() {
  NormalizationStats n;
  n.variant = "np_bps";
  n.count = 1;
  n.x_mean = at::zeros({1200}, at::kDouble);
  n.x_std = at::full({1200}, 0.05, at::kDouble);
  n.obj_mean = at::zeros({3079}, at::kDouble);
  n.obj_std = at::ones({3079}, at::kDouble);
  n.c_mean = at::full({2048}, 0.05, at::kDouble);
  n.c_std = at::full({2048}, 0.05, at::kDouble);
  return n;
}

std::shared_ptr<const DiffusionModel> random_model(const std::string& kind, int which) {
  Checkpoint c;
  c.info.network = sized(kind, which);
  c.info.network.dropout = 0.0;
  c.info.basis_points = at::rand({1024, 3});
  c.info.normalization = unit_stats();
  torch::manual_seed(1);
  Denoiser net(c.info.network);
  c.weights = state_of(*net);
  return std::make_shared<const DiffusionModel>(std::move(c), kind + " (random)");
}

// args: size, samples, DDIM steps (0 = DDPM 50)
void BM_DiffusionSampleWindow(benchmark::State& state) {
  runtime::set_threads(2);
  const int which = static_cast<int>(state.range(0));
  const auto contact = random_model("contact", which), motion = random_model("motion", which);
  const at::Tensor O = at::randn({64, 1024, 3}), G = at::randn({64, 7});
  const at::Tensor points = at::rand({64, 1024, 3}) * 0.2;
  GenerateOptions o;
  o.samples = static_cast<int>(state.range(1));
  if (state.range(2) > 0) o.sampler = {"ddim", static_cast<int>(state.range(2)), 0.0};
  auto gen = at::detail::createCPUGenerator(2);
  for (auto _ : state) {
    const at::Tensor C = contact->generate(O, G, {}, nullptr, o, gen);
    const ContactMapGuidance guidance(points, C, 1.0);
    benchmark::DoNotOptimize(motion->generate(O, G, C, &guidance, o, gen));
  }
  state.SetLabel(std::string(size_name(which)) + ", " + std::to_string(o.samples) + " samples, " +
                 (state.range(2) > 0 ? "DDIM " + std::to_string(state.range(2)) : std::string("DDPM 50")));
}
BENCHMARK(BM_DiffusionSampleWindow)
    ->Args({3, 1, 0})
    ->Args({0, 1, 0})
    ->Args({0, 10, 0})
    ->Args({1, 1, 0})
    ->Args({1, 10, 0})
    ->Args({1, 1, 10})
    ->Args({3, 1, 10})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The right wrist pinned, with its orientation, at frames 32 and 63.
void add_two_wrist_pins(HandConstraints& c) {
  for (std::int64_t f : {32, 63}) {
    HandPin pin;
    pin.hand = 1;
    pin.frames = {f, f};
    pin.wrist = Eigen::Vector3d(0.05, 0.3, -0.1);
    pin.rotation = Eigen::Quaterniond(axis_angle_to_matrix(Eigen::Vector3d(0, 1.2, 0)));
    c.pins.push_back(pin);
  }
}

// One 64-frame window of the shipped size (contact + motion, 1 sample, DDPM 50, guidance),
// unconstrained (arg 0) or directed (arg 1): the right hand on the top part throughout, the
// left hand kept off for 20 frames, the right wrist pinned (with its orientation) at two
// frames — each constraint imposed on all 50 steps of its sampler. Args 2 and 3 split the
// cost: the contact rules alone, the hand pins alone.
void BM_DiffusionSampleWindowDirected(benchmark::State& state) {
  runtime::set_threads(2);
  const bool directed = state.range(0) != 0;
  const bool with_rules = directed && state.range(0) != 3, with_pins = directed && state.range(0) != 2;
  const auto contact = random_model("contact", 0), motion = random_model("motion", 0);
  const at::Tensor O = at::randn({64, 1024, 3}), G = at::randn({64, 7});
  const ArticulatedObject& object = bench::bench_object();
  const std::int64_t top = object.top.num_vertices(), bottom = object.bottom.num_vertices();
  const at::Tensor hits = at::cat({at::arange(512) % top, top + at::arange(512) % bottom}).unsqueeze(0).expand({64, 1024}).contiguous();
  // The object points: the hit vertices of the closed object (its surface, as in a run).
  at::Tensor vertices = at::empty({top + bottom, 3}, at::kDouble);
  std::copy(object.top.vertices.data(), object.top.vertices.data() + 3 * top, vertices.data_ptr<double>());
  std::copy(object.bottom.vertices.data(), object.bottom.vertices.data() + 3 * bottom, vertices.data_ptr<double>() + 3 * top);
  const at::Tensor points = vertices.to(at::kFloat).index_select(0, hits[0]).unsqueeze(0).expand({64, 1024, 3}).contiguous();
  HandConstraints c;
  c.contacts.push_back({1, {0, 63}, ContactPart::Top, std::nullopt, 0.03, {}});
  c.contacts.push_back({0, {10, 29}, ContactPart::None, std::nullopt, 0.03, {}});
  add_two_wrist_pins(c);
  const ContactRules rules(c, object, hits);
  const HandPins pins(c, test::shipped_hands(), at::zeros({64, 7}, at::kDouble), points);
  GenerateOptions o;
  o.samples = 1;
  auto gen = at::detail::createCPUGenerator(2);
  for (auto _ : state) {
    const at::Tensor C = contact->generate(O, G, {}, nullptr, o, gen, with_rules ? &rules : nullptr);
    const ContactMapGuidance guidance(points, C, 1.0);
    benchmark::DoNotOptimize(motion->generate(O, G, C, &guidance, o, gen, with_pins ? &pins : nullptr));
  }
  static const char* const labels[] = {"", ", directed", ", contact rules only", ", hand pins only"};
  state.SetLabel(std::string("tiny (shipped), 1 sample, DDPM 50") + labels[state.range(0)]);
}
BENCHMARK(BM_DiffusionSampleWindowDirected)->DenseRange(0, 3)->MinTime(6)->Unit(benchmark::kMillisecond)->UseRealTime();

// One step's in-painting of HandPins on a 64-frame window: two wrist pins with their
// orientation (arg 0) or a hand kept off for 20 frames (arg 1).
void BM_HandPinsImpose(benchmark::State& state) {
  runtime::set_threads(2);
  const at::Tensor points = at::rand({64, 1024, 3}) * 0.2;
  HandConstraints c;
  if (state.range(0) == 1)
    c.contacts.push_back({0, {10, 29}, ContactPart::None, std::nullopt, 0.03, {}});
  else
    add_two_wrist_pins(c);
  const HandPins pins(c, test::shipped_hands(), at::zeros({64, 7}, at::kDouble), points);
  const at::Tensor x0 = at::rand({1, 64, 1200}) * 0.2;
  for (auto _ : state) benchmark::DoNotOptimize(pins.impose(x0, 0, 10, 50));
  state.SetLabel(state.range(0) == 0 ? "64 frames, 2 wrist pins" : "64 frames, a hand kept off for 20 frames");
}
BENCHMARK(BM_HandPinsImpose)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DiffusionGuidanceStep(benchmark::State& state) {
  runtime::set_threads(static_cast<int>(state.range(0)));
  const at::Tensor points = at::rand({64, 1024, 3}) * 0.2;
  const at::Tensor target = at::rand({64, 2, 1024}) * 0.1;
  const ContactMapGuidance g(points, target, 1.0);
  const at::Tensor x0 = at::rand({1, 64, 1200}) * 0.2;
  for (auto _ : state) benchmark::DoNotOptimize(g.correction(x0, 0, 10, 50));
  state.SetLabel("64 frames, 1 sample");
}
BENCHMARK(BM_DiffusionGuidanceStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// One denoiser forward over a 64-frame window (conditions encoded once, as in sampling).
// args: size, batch (2 = a CFG pair), fused (1 = the sampling path, 0 = libtorch's module).
void BM_DiffusionDenoiserForward(benchmark::State& state) {
  runtime::set_threads(2);
  DenoiserConfig c = sized("motion", static_cast<int>(state.range(0)));
  c.dropout = 0.0;
  torch::manual_seed(1);
  Denoiser net(c);
  net->eval();
  const int64_t B = state.range(1);
  const bool fused = state.range(2) != 0;
  torch::NoGradGuard ng;
  const at::Tensor cond = net->encode_conditions(at::randn({B, 64, c.object_condition_size}));
  const at::Tensor x = at::randn({B, 64, c.sample_size}), t = at::full({B}, 10, at::kLong);
  if (!fused) net->train();  // the module path (dropout is 0, so the same numbers)
  for (auto _ : state) benchmark::DoNotOptimize(net->forward(x, t, cond));
  state.SetLabel(std::string(size_name(static_cast<int>(state.range(0)))) + ", batch " + std::to_string(B) +
                 (fused ? ", fused layers" : ", module layers"));
}
BENCHMARK(BM_DiffusionDenoiserForward)
    ->Args({1, 1, 1})
    ->Args({1, 1, 0})
    ->Args({1, 2, 1})
    ->Args({1, 2, 0})
    ->Args({3, 2, 1})
    ->Args({3, 2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace bimart::diffusion
