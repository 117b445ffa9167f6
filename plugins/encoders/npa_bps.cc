// encoder.npa_bps: NPA-BPS (ablation): 1024 points in the unit ball, object scaled by s_o, parts ignored.
#include "bps_encoder.h"
#include "core/pipeline/plugin.h"

namespace bimart {
namespace {

class NpaBpsEncoder : public BpsEncoder<BpsVariant::PartAgnostic> {
 public:
  using BpsEncoder::BpsEncoder;
  static StageSpec spec() { return make_spec("npa_bps", "NPA-BPS (ablation): 1024 points in the unit ball, object scaled by s_o, parts ignored"); }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::NpaBpsEncoder)
