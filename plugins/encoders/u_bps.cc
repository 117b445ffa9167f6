// encoder.u_bps: U-BPS (ablation): 1024 points in a 0.5 m ball, object in metres, parts ignored.
#include "bps_encoder.h"
#include "core/pipeline/plugin.h"

namespace bimart {
namespace {

class UBpsEncoder : public BpsEncoder<BpsVariant::Uniform> {
 public:
  using BpsEncoder::BpsEncoder;
  static StageSpec spec() { return make_spec("u_bps", "U-BPS (ablation): 1024 points in a 0.5 m ball, object in metres, parts ignored"); }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::UBpsEncoder)
