// The metric.* plug-ins, loaded from their shared library exactly as a pipeline loads them,
// agree with core/metrics on a synthetic sequence (real hands on a real object).
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/metrics/hand_vertices.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/families/families.h"
#include "core/object/object_state.h"
#include "core/pipeline/context.h"
#include "core/pipeline/plugin_loader.h"
#include "core/pipeline/registry.h"
#include "core/synth/interaction.h"
#include "core/util/data_path.h"

namespace bimart {
namespace {

struct Fixture {
  ArticulatedObject object;
  Trajectory trajectory;
  HandMotion motion;
  SequenceMetrics expected;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    x.object = make_object("box", 3);
    const ObjectDistance d(x.object);
    const HandModel left = load_hand_model(find_data_file("models/hand/mano_left.npz"));
    const HandModel right = load_hand_model(find_data_file("models/hand/mano_right.npz"));
    for (std::uint64_t seed = 1;; ++seed) {  // the first trajectory with a motion
      x.trajectory = plan_trajectory(x.object, SequenceKind::Use, seed);
      try {
        x.motion = synthesize_hands(x.object, d, {&left, &right}, x.trajectory, seed);
        break;
      } catch (const Error&) {
        if (seed > 5) throw;
      }
    }
    // For a stretch of frames, put one right-hand vertex at the centre of the bottom part
    // (deep inside), so that Pen has frames to count.
    SequenceData data;
    data.object_states = x.trajectory.tensor();
    x.motion.vertices = hand_vertices(x.motion).clone();
    const Eigen::Vector3d centre = x.object.bottom.vertices.colwise().mean().transpose();
    for (int t = 40; t < 60; ++t) {
      const Eigen::Vector3d c = canonical_to_world(x.trajectory.states[t]) * centre;
      for (int k = 0; k < 3; ++k) x.motion.vertices[1][t][0][k] = static_cast<float>(c[k]);
    }
    data.hand_vertices = x.motion.vertices;
    x.expected = evaluate_sequence(x.object, d, data);
    return x;
  }();
  return f;
}

MetricResult run_metric(const std::string& key, const Params& params) {
  static Registry registry;
  static PluginLoader loader(registry);
  if (!registry.find(key)) loader.load(builtin_plugin_dir() + "/libbimart_metrics.so");
  const StageEntry& e = registry.get(key);
  Context context;
  context.put<HandMotion>("seq.hand_params", fixture().motion);
  context.put<ArticulatedObject>("seq.object", fixture().object);
  context.put<at::Tensor>("seq.object_states", fixture().trajectory.tensor());
  StageIO io(context, e.spec, "m",
             {{"hand_params", "seq.hand_params"}, {"object", "seq.object"}, {"object_states", "seq.object_states"}},
             params, 1);
  e.factory(params)->run(io);
  return context.get<MetricResult>("m.result");
}

TEST(MetricPlugins, AgreeWithTheLibraryOnASyntheticSequence) {
  const SequenceMetrics& x = fixture().expected;
  ASSERT_EQ(x.pen_5mm.hits, 20);
  Params pen;
  pen.set("threshold", 0.005);
  const MetricResult p = run_metric("metric.penetration", pen);
  EXPECT_EQ(p.name, "Pen 5mm");
  EXPECT_EQ(p.numerator, x.pen_5mm.hits);
  EXPECT_EQ(p.denominator, x.pen_5mm.frames);
  pen.set("threshold", 0.01);
  EXPECT_EQ(run_metric("metric.penetration", pen).numerator, x.pen_1cm.hits);
  const MetricResult c = run_metric("metric.contact", {});
  EXPECT_EQ(c.numerator, x.contact.hits);
  EXPECT_EQ(c.denominator, x.contact.frames);
  EXPECT_GT(c.denominator, 0);
  const MetricResult a = run_metric("metric.articulation", {});
  EXPECT_EQ(a.numerator, x.articulation.hits);
  EXPECT_EQ(a.denominator, x.articulation.frames);
  EXPECT_GT(a.denominator, 0);
  EXPECT_NEAR(run_metric("metric.accel", {}).value, 100 * x.accel, 1e-9);
}

}  // namespace
}  // namespace bimart
