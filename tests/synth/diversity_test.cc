// The data issue's bars that need many sequences (label "long", ~1 min): diversity (Mul over
// 10 seeds of one trajectory), the share of use sequences driven by the left hand.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include "core/metrics/hand_vertices.h"
#include "core/metrics/multimodality.h"
#include "core/object/families/families.h"
#include "core/synth/interaction.h"
#include "shipped_hands.h"
#include "core/util/error.h"

namespace bimart {
namespace {

const std::array<const HandModel*, 2>& hands() { return test::shipped_hands(); }

// Mul (DESIGN §6) of 10 seeds on one trajectory, in metres; seeds without a motion skipped.
double mul_of_ten_seeds(const std::string& category, SequenceKind kind, std::uint64_t seed, int* found) {
  const ArticulatedObject o = make_object(category, seed);
  const ObjectDistance d(o);
  const Trajectory t = plan_trajectory(o, kind, seed);
  std::vector<at::Tensor> samples;
  for (std::uint64_t s = 0; s < 10; ++s) {
    try {
      samples.push_back(hand_vertices(synthesize_hands(o, d, hands(), t, 100 + s)));
    } catch (const Error&) {
    }
  }
  *found = static_cast<int>(samples.size());
  return samples.size() >= 2 ? multimodality(samples) : 0.0;
}

TEST(Diversity, TenSeedsOfOneTrajectoryAreAtLeastThreeCentimetresApart) {
  for (const auto& [category, kind] : {std::pair{"box", SequenceKind::Grab}, {"laptop", SequenceKind::Grab},
                                       {"microwave", SequenceKind::Use}, {"waffleiron", SequenceKind::Use}}) {
    int found = 0;
    const double mul = mul_of_ten_seeds(category, kind, 2, &found);
    EXPECT_GE(found, 6) << category;
    EXPECT_GE(100 * mul, 3.0) << category << " " << kind_name(kind);
    std::cout << category << " " << kind_name(kind) << ": Mul " << 100 * mul << " cm over " << found << " seeds\n";
  }
}

TEST(Diversity, EitherHandDrivesUseSequences) {
  int left = 0, total = 0;
  std::uint64_t hand_seed = 0;  // a new one for every sequence: the driver is drawn from it
  for (const char* category : {"box", "microwave", "waffleiron", "capsulemachine", "mixer"})
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      ++hand_seed;
      const ArticulatedObject o = make_object(category, seed);
      const ObjectDistance d(o);
      const Trajectory t = plan_trajectory(o, SequenceKind::Use, seed);
      InteractionInfo info;
      try {
        synthesize_hands(o, d, hands(), t, hand_seed, {}, &info);
      } catch (const Error&) {
        continue;
      }
      ++total;
      left += info.driver == 0;
    }
  std::cout << "left drives " << left << " of " << total << " use sequences\n";
  ASSERT_GE(total, 30);
  EXPECT_GE(left, 0.3 * total);
  EXPECT_LE(left, 0.7 * total);
}

}  // namespace
}  // namespace bimart
