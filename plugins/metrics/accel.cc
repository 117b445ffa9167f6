// metric.accel: Accel (DESIGN §6), cm per frame², lower is better.
#include "core/metrics/accel.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/sequence_metrics.h"
#include "core/pipeline/plugin.h"
#include "stages/metric.h"

namespace bimart {
namespace {

class AccelMetric : public Metric {
 public:
  static StageSpec spec() {
    return StageSpec::of<Metric>("accel", "Accel: mean ||v_t - 2 v_{t-1} + v_{t-2}|| of the hand vertices (cm/frame²)")
        .input<HandMotion>("hand_params",
                           "both hands, world frame; `vertices` used when present, else posed with "
                           "models/hand/mano_{left,right}.npz");
  }
  explicit AccelMetric(const Params&) {}

  void run(StageIO& io) override {
    SequenceMetrics m;
    m.accel = mean_acceleration(hand_vertices(io.in<HandMotion>("hand_params")));
    io.out("result", accel_result({m}));
  }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::AccelMetric)
