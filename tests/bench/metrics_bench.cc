// The paper's metrics for one sequence, one thread: 64 frames, 2 × 778 hand vertices near
// the surface of a ~4,000-vertex object (issue target: all metrics under 0.5 s).
// Run: bimart_benchmarks --benchmark_filter='Metrics'
#include <benchmark/benchmark.h>

#include <random>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/metrics/multimodality.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/families/primitives.h"
#include "core/object/object_state.h"
#include "bench_object.h"

namespace bimart {
namespace {

constexpr int kFrames = 64;
constexpr int kHandVertices = 778;

using bench::bench_object;

// The object turns, moves and opens; each hand's vertices are object surface points (left:
// bottom part, right: top part) jittered by 1 cm, so about half are inside. With `outside`
// they are instead pushed 15% away from the part's centre (all outside, most within 2 cm):
// no vertex inside, so fewer distances can be skipped.
SequenceData bench_sequence(std::uint64_t seed, bool outside = false) {
  const ArticulatedObject& o = bench_object();
  SequenceData d;
  d.name = "bench";
  d.object_states = at::zeros({kFrames, 7});
  for (int t = 0; t < kFrames; ++t) {
    d.object_states[t][0] = 0.02 * t;
    d.object_states[t][2] = 0.01 * t;
    d.object_states[t][4] = 0.003 * t;
  }
  d.hand_vertices = at::zeros({2, kFrames, kHandVertices, 3}, at::kFloat);
  auto v = d.hand_vertices.accessor<float, 4>();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, 0.01);
  for (int t = 0; t < kFrames; ++t) {
    const ObjectState s = ObjectState::from_row(d.object_states[t].contiguous().data_ptr<float>());
    const PosedObject p = pose_world(o, s);
    for (int h = 0; h < 2; ++h) {
      const PartVertices& part = h == 0 ? p.bottom : p.top;
      std::uniform_int_distribution<Eigen::Index> pick(0, part.rows() - 1);
      const Eigen::RowVector3d centre = part.colwise().mean();
      for (int i = 0; i < kHandVertices; ++i) {
        const Eigen::Index k = pick(rng);
        const Eigen::RowVector3d x = outside ? Eigen::RowVector3d(centre + 1.15 * (part.row(k) - centre))
                                             : Eigen::RowVector3d(part.row(k));
        for (int c = 0; c < 3; ++c) v[h][t][i][c] = static_cast<float>(x(c) + (outside ? 0.0 : noise(rng)));
      }
    }
  }
  // CM inputs: 100 keypoints per hand, any 1024 hit vertices, any conditioning maps.
  d.hand_keypoints = d.hand_vertices.slice(2, 0, 100).contiguous();
  const int64_t nv = o.top.num_vertices() + o.bottom.num_vertices();
  d.basis_hit_indices = at::randint(nv, {kFrames, 1024}, at::kLong);
  d.contact_maps = at::rand({kFrames, 2, 1024}) * 0.05;
  return d;
}

void BM_MetricsDistanceTrees(benchmark::State& state) {
  at::set_num_threads(1);
  for (auto _ : state) benchmark::DoNotOptimize(ObjectDistance(bench_object()));
  state.counters["object_vertices"] =
      static_cast<double>(bench_object().top.num_vertices() + bench_object().bottom.num_vertices());
}
BENCHMARK(BM_MetricsDistanceTrees)->Unit(benchmark::kMillisecond);

// Accel, Pen 1cm, Pen 5mm, Con, Art and CM of one sequence, trees built beforehand.
void BM_MetricsOneSequence(benchmark::State& state) {
  at::set_num_threads(1);
  const ObjectDistance dist(bench_object());
  const SequenceData d = bench_sequence(1);
  SequenceMetrics m;
  for (auto _ : state) benchmark::DoNotOptimize(m = evaluate_sequence(bench_object(), dist, d));
  state.counters["pen_1cm_frames"] = static_cast<double>(m.pen_1cm.hits);
  state.counters["hand_vertices"] = 2 * kHandVertices;
}
BENCHMARK(BM_MetricsOneSequence)->Unit(benchmark::kMillisecond);

// The same with every hand vertex outside the object, near it.
void BM_MetricsOneSequenceHandsOutside(benchmark::State& state) {
  at::set_num_threads(1);
  const ObjectDistance dist(bench_object());
  const SequenceData d = bench_sequence(1, true);
  SequenceMetrics m;
  for (auto _ : state) benchmark::DoNotOptimize(m = evaluate_sequence(bench_object(), dist, d));
  state.counters["con_frames"] = static_cast<double>(m.contact.hits);
}
BENCHMARK(BM_MetricsOneSequenceHandsOutside)->Unit(benchmark::kMillisecond);

// Everything including building the trees and Mul over 2 samples.
void BM_MetricsOneSequenceWithTreesAndMul(benchmark::State& state) {
  at::set_num_threads(1);
  const SequenceData d = bench_sequence(1);
  const at::Tensor other = bench_sequence(2).hand_vertices;
  for (auto _ : state) {
    const ObjectDistance dist(bench_object());
    benchmark::DoNotOptimize(evaluate_sequence(bench_object(), dist, d));
    benchmark::DoNotOptimize(multimodality({d.hand_vertices, other}));
  }
}
BENCHMARK(BM_MetricsOneSequenceWithTreesAndMul)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bimart
