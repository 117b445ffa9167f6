// metric.articulation: Art: among frames where the hinge angle changes, % with a hand vertex within 5 mm of (or inside) the top part (DESIGN §6).
#include "core/pipeline/plugin.h"
#include "metric_inputs.h"

namespace bimart {
namespace {

class ArticulationMetric : public Metric {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Metric>("articulation", "Art: among frames where the hinge angle changes, % with a hand vertex within 5 mm of (or inside) the top part");
    declare_hand_object_inputs(s);
    return s;
  }
  explicit ArticulationMetric(const Params&) {}

  void run(StageIO& io) override {
    io.out("result", frame_share_result("Art", true, {evaluate_inputs(io)}, &SequenceMetrics::articulation));
  }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ArticulationMetric)
