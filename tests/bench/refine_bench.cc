// MANO fit and refinement of one 64-frame two-hand sample (issue 7 target: both under 2 s
// on the 2-core machine; the authors' GPU pipeline takes about 300 s per sample).
// Run: bimart_benchmarks --benchmark_filter='Refine|ManoFit'
#include <benchmark/benchmark.h>

#include "core/refine/mano_fit.h"
#include "core/refine/refinement.h"
#include "refine_sample.h"

namespace bimart {
namespace {

void BM_ManoFit(benchmark::State& state) {
  const bench::RefineSample& s = bench::refine_sample();
  const at::Tensor H = hand_features_to_world(s.keypoints, s.states).positions;
  ManoFitOptions o;
  o.threads = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(fit_mano(s.models(), H, o));
}
BENCHMARK(BM_ManoFit)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Refine(benchmark::State& state) {
  const bench::RefineSample& s = bench::refine_sample();
  const ObjectDistance distance(s.object);
  const HandMotion fit = fit_mano(s.models(), hand_features_to_world(s.keypoints, s.states).positions);
  RefineOptions o;
  o.threads = static_cast<int>(state.range(0));
  RefineReport report;
  for (auto _ : state) benchmark::DoNotOptimize(refine_hands(s.models(), distance, s.states, s.keypoints, fit, o, &report));
  state.counters["outer"] = report.hands[0].outer_iterations + report.hands[1].outer_iterations;
  state.counters["steps"] = report.hands[0].iterations + report.hands[1].iterations;
}
BENCHMARK(BM_Refine)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace bimart
