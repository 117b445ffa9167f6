// metric.contact_map: CM (DESIGN §6), cm: mean |C(keypoints of the generated hands) -
// C(conditioning)| over 2 × 1024 entries and all frames.
#include "core/metrics/contact_map_error.h"
#include "core/pipeline/plugin.h"
#include "metric_inputs.h"

namespace bimart {
namespace {

class ContactMapMetric : public Metric {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<Metric>("contact_map", "CM: mean absolute difference between the contact map of the generated hands' keypoints and the conditioning one (cm)");
    declare_hand_object_inputs(s)
        .input<at::Tensor>("contact_maps", "C: [N, 2, 1024] float32, metres: the maps that conditioned the motion")
        .input<at::Tensor>("basis_hit_indices", "[N, 1024] int64, from the encoder");
    return s;
  }
  explicit ContactMapMetric(const Params&) {}

  void run(StageIO& io) override {
    const HandMotion& motion = io.in<HandMotion>("hand_params");
    SequenceMetrics m;
    m.contact_map = contact_map_error(io.in<ArticulatedObject>("object"), io.in<at::Tensor>("object_states"),
                                      io.in<at::Tensor>("basis_hit_indices"), hand_keypoints(motion),
                                      io.in<at::Tensor>("contact_maps"));
    io.out("result", contact_map_result({m}));
  }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ContactMapMetric)
