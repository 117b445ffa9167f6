// Object and hand features, one thread: NP-BPS for 64 frames of a ~4,000-vertex object
// (issue target: under 20 ms), contact maps and X = [H | D] for 64 frames of two hands.
// Run: bimart_benchmarks --benchmark_filter='NpBps|ContactMap|HandFeatures'
#include <benchmark/benchmark.h>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/features/bps.h"
#include "core/features/contact_map.h"
#include "core/features/hand_features.h"
#include "core/hand/hand_model.h"
#include "core/hand/lbs_torch.h"
#include "core/object/families/primitives.h"
#include "core/util/data_path.h"
#include "bench_object.h"

namespace bimart {
namespace {

constexpr int kFrames = 64;

const ArticulatedObject& object() { return bench::bench_object(); }

at::Tensor states() {
  at::Tensor s = at::zeros({kFrames, 7});
  for (int t = 0; t < kFrames; ++t) {
    s[t][0] = 0.02 * t;  // every frame a new angle: no frame reuse
    s[t][4] = 0.01 * t;
  }
  return s;
}

void BM_NpBps64Frames(benchmark::State& state) {
  at::set_num_threads(1);
  const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(BpsVariant::PerPart)));
  const at::Tensor s = states();
  for (auto _ : state) benchmark::DoNotOptimize(encode_object(object(), s, basis, BpsVariant::PerPart));
  state.counters["vertices"] = double(object().top.num_vertices() + object().bottom.num_vertices());
}
BENCHMARK(BM_NpBps64Frames)->Unit(benchmark::kMillisecond);

at::Tensor hand_vertices() {
  std::vector<at::Tensor> hands;
  at::manual_seed(0);
  for (const char* f : {"models/hand/mano_left.npz", "models/hand/mano_right.npz"}) {
    const HandModelTensors m = HandModelTensors::from(load_hand_model(find_data_file(f)));
    hands.push_back(lbs(m, at::randn({kFrames, 3}) * 0.3, at::randn({kFrames, 45}) * 0.2,
                        at::randn({kFrames, 3}) * 0.05, at::zeros({kFrames, 10}))
                        .vertices);
  }
  return at::stack(hands, 0);
}

void BM_ContactMap64Frames(benchmark::State& state) {
  at::set_num_threads(1);
  const at::Tensor obj = at::rand({kFrames, 1024, 3}) * 0.2;
  // Second argument: points per hand, 778 (mesh: data, metrics) or 100 (keypoints: guidance, CM).
  const at::Tensor hands = hand_vertices().slice(2, 0, state.range(1));
  for (auto _ : state)
    benchmark::DoNotOptimize(state.range(0) ? contact_maps_exhaustive(obj, hands) : contact_maps(obj, hands));
  state.SetLabel(state.range(0) ? "pairwise (libtorch)" : "k-d trees");
}
BENCHMARK(BM_ContactMap64Frames)->Args({0, 778})->Args({1, 778})->Args({0, 100})->Args({1, 100})->Unit(benchmark::kMillisecond);

void BM_HandFeatures64Frames(benchmark::State& state) {
  at::set_num_threads(1);
  const HandModel m = load_hand_model(find_data_file("models/hand/mano_right.npz"));
  const at::Tensor hands = hand_vertices();
  const at::Tensor s = states();
  for (auto _ : state) benchmark::DoNotOptimize(hand_features(hands, m.keypoints, object(), s));
}
BENCHMARK(BM_HandFeatures64Frames)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bimart
