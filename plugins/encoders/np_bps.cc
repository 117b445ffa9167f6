// encoder.np_bps: NP-BPS (the method): 512 points in the unit ball mapped to each part, object scaled by s_o.
#include "bps_encoder.h"
#include "core/pipeline/plugin.h"

namespace bimart {
namespace {

class NpBpsEncoder : public BpsEncoder<BpsVariant::PerPart> {
 public:
  using BpsEncoder::BpsEncoder;
  static StageSpec spec() { return make_spec("np_bps", "NP-BPS (the method): 512 points in the unit ball mapped to each part, object scaled by s_o"); }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::NpBpsEncoder)
