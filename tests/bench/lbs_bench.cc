// Linear blend skinning of 64 frames x 2 hands with an ~800-vertex random model, one thread:
// the templated version in double (as Ceres fits call it) and the batched torch version.
// Run: bimart_benchmarks --benchmark_filter=Lbs
#include <benchmark/benchmark.h>

#include <random>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/hand/lbs.h"
#include "core/hand/lbs_torch.h"
#include "core/runtime/allocator.h"
#include "core/runtime/blas.h"
#include "tests/hand/synthetic_model.h"

namespace bimart {
namespace {

constexpr int kVertices = 800;
constexpr int kHands = 64 * 2;

const HandModel& model() {
  static const HandModel m = testing::make_synthetic_hand(kVertices, 1);
  return m;
}

// 128 hands of 61 random inputs each (rot, pose, trans, betas).
std::vector<double> random_inputs() {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<double> x(kHands * 61);
  for (double& v : x) v = u(rng);
  return x;
}

void BM_LbsTemplatedDouble(benchmark::State& state) {
  const HandModel& m = model();
  const std::vector<double> x = random_inputs();
  LbsResult<double> out;
  for (auto _ : state) {
    for (int h = 0; h < kHands; ++h) {
      const double* p = &x[h * 61];
      lbs(m, p, p + 3, p + 48, p + 51, &out);
      benchmark::DoNotOptimize(out.vertices.data());
    }
  }
  state.SetItemsProcessed(state.iterations() * kHands);
}
BENCHMARK(BM_LbsTemplatedDouble)->Unit(benchmark::kMillisecond);

void torch_lbs(benchmark::State& state, at::ScalarType dtype, bool backward) {
  at::set_num_threads(1);
  const HandModelTensors mt = HandModelTensors::from(model(), dtype);
  const std::vector<double> x = random_inputs();
  at::Tensor all = at::from_blob(const_cast<double*>(x.data()), {kHands, 61}, at::kDouble).to(dtype);
  if (backward) all.requires_grad_(true);
  for (auto _ : state) {
    const LbsTensors out = lbs(mt, all.slice(1, 0, 3), all.slice(1, 3, 48), all.slice(1, 48, 51),
                               all.slice(1, 51, 61));
    if (backward) {
      out.vertices.sum().backward();
      all.mutable_grad().reset();
    }
    benchmark::DoNotOptimize(out.vertices.data_ptr());
  }
  state.SetItemsProcessed(state.iterations() * kHands);
}
void BM_LbsTorchFloat32(benchmark::State& s) { torch_lbs(s, at::kFloat, false); }
void BM_LbsTorchFloat64(benchmark::State& s) { torch_lbs(s, at::kDouble, false); }
void BM_LbsTorchFloat32ForwardBackward(benchmark::State& s) { torch_lbs(s, at::kFloat, true); }
BENCHMARK(BM_LbsTorchFloat32)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbsTorchFloat64)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbsTorchFloat32ForwardBackward)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bimart

int main(int argc, char** argv) {
  bimart::runtime::ensure_blas_kernel(argc, argv);
  bimart::runtime::tune_allocator();  // as bimart does
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
