// contact.ground_truth: the contact maps C of known hands (e.g. trajectory.sequence's ground
// truth) on the encoder's basis rows, computed as the training data's are
// (world_contact_maps, core/features/contact_map.h). It stands where contact.diffusion does:
// an oracle that tells what the motion stages make of perfect contact maps
// (docs/results.md, "w GT C"). It ignores the object features it is wired to.
#include "core/features/contact_map.h"
#include "core/metrics/hand_vertices.h"
#include "core/pipeline/plugin.h"
#include "stages/contact_generator.h"

namespace bimart {
namespace {

class GroundTruthContact : public ContactGenerator {
 public:
  static StageSpec spec() {
    return StageSpec::of<ContactGenerator>("ground_truth", "contact maps of known hands (an oracle, for comparisons)")
        .input<HandMotion>("ground_truth", "the hands, world frame")
        .input<ArticulatedObject>("object", "the object, canonical frame")
        .input<at::Tensor>("object_states", "[N, 7]")
        .input<at::Tensor>("basis_hit_indices", "[N, 1024] the encoder's hit vertices");
  }
  explicit GroundTruthContact(const Params&) {}
  void run(StageIO& io) override {
    const at::Tensor C = world_contact_maps(io.in<ArticulatedObject>("object"), io.in<at::Tensor>("object_states"),
                                            io.in<at::Tensor>("basis_hit_indices"),
                                            hand_vertices(io.in<HandMotion>("ground_truth")));
    io.out("contact_maps", C.to(at::kFloat).contiguous());
  }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::GroundTruthContact)
