// metric.contact: Con: among frames where the object moves, % with a hand vertex within 5 mm of (or inside) the object (DESIGN §6).
#include "core/pipeline/plugin.h"
#include "metric_inputs.h"

namespace bimart {
namespace {

class ContactMetric : public Metric {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Metric>("contact", "Con: among frames where the object moves, % with a hand vertex within 5 mm of (or inside) the object");
    declare_hand_object_inputs(s);
    return s;
  }
  explicit ContactMetric(const Params&) {}

  void run(StageIO& io) override {
    io.out("result", frame_share_result("Con", true, {evaluate_inputs(io)}, &SequenceMetrics::contact));
  }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ContactMetric)
