// metric.mul: Mul (DESIGN §6), cm, higher is better: S generated samples of one trajectory
// come in as one list (input `hand_samples`, S >= 2, e.g. from a generator run S times or
// with num_samples = S); the value is the mean over sample pairs of the mean per-vertex
// distance.
#include <vector>

#include "core/metrics/hand_vertices.h"
#include "core/metrics/multimodality.h"
#include "core/metrics/sequence_metrics.h"
#include "core/pipeline/plugin.h"
#include "stages/metric.h"

namespace bimart {
namespace {

class MulMetric : public Metric {
 public:
  static StageSpec spec() {
    return StageSpec::of<Metric>("mul", "Mul: mean pairwise per-vertex distance between S samples of one trajectory (cm)")
        .input<std::vector<HandMotion>>("hand_samples",
                                        "S >= 2 hand motions generated for the same trajectory (world frame)");
  }
  explicit MulMetric(const Params&) {}

  void run(StageIO& io) override {
    std::vector<at::Tensor> v;
    for (const HandMotion& m : io.in<std::vector<HandMotion>>("hand_samples")) v.push_back(hand_vertices(m));
    io.out("result", mul_result({multimodality(v)}));
  }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::MulMetric)
