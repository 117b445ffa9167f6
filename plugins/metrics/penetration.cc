// metric.penetration: Pen (DESIGN §6), % of frames whose deepest hand vertex is more than
// `threshold` inside the object; the paper reports 0.01 (Pen 1cm) and 0.005 (Pen 5mm).
#include <cmath>

#include <fmt/format.h>

#include "core/metrics/frame_depths.h"
#include "core/metrics/penetration.h"
#include "core/pipeline/plugin.h"
#include "metric_inputs.h"

namespace bimart {
namespace {

class PenetrationMetric : public Metric {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Metric>("penetration", "Pen: % of frames with a hand vertex deeper than the threshold inside the object")
                      .param("threshold", kPenetration1cm, "depth (m), strict: 0.01 for Pen 1cm, 0.005 for Pen 5mm");
    declare_hand_object_inputs(s);
    return s;
  }
  explicit PenetrationMetric(const Params& p) : threshold_(p.number("threshold")) {
    if (!(threshold_ >= 0) || !std::isfinite(threshold_))
      throw Error("threshold must be a depth >= 0 in metres, got " + std::to_string(threshold_));
  }

  void run(StageIO& io) override {
    const ArticulatedObject& object = io.in<ArticulatedObject>("object");
    const ObjectDistance distance(object);
    const FrameDepths d = frame_depths(distance, io.in<at::Tensor>("object_states"),
                                       hand_vertices(io.in<HandMotion>("hand_params")));
    SequenceMetrics s;
    s.pen_1cm = penetration_frames(d, threshold_);  // the field carries this threshold's counts
    const std::string name = threshold_ == kPenetration1cm   ? "Pen 1cm"
                             : threshold_ == kPenetration5mm ? "Pen 5mm"
                                                             : fmt::format("Pen {:g}mm", threshold_ * 1000);
    io.out("result", frame_share_result(name, false, {s}, &SequenceMetrics::pen_1cm));
  }

 private:
  double threshold_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::PenetrationMetric)
