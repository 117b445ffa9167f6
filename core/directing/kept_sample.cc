#include "core/directing/kept_sample.h"

#include <ATen/ATen.h>
#include <fmt/format.h>

#include "core/features/hand_features.h"
#include "core/hand/keypoints.h"
#include "core/io/sequence.h"
#include "core/refine/mano_fit.h"

namespace bimart {

KeptFrames::KeptFrames(at::Tensor known, const std::vector<double>& weights)
    : known_(known.to(at::kFloat).contiguous()) {
  if (known_.dim() != 2 || known_.size(0) != static_cast<std::int64_t>(weights.size()))
    throw Error(fmt::format("kept frames: {} weights for values of shape {}", weights.size(), c10::str(known_.sizes())));
  weight_ = at::tensor(weights, at::kDouble).to(at::kFloat).view({-1, 1});
}

at::Tensor KeptFrames::impose(const at::Tensor& x0, std::int64_t first, int /*step*/, int /*num_steps*/) const {
  const std::int64_t T = x0.size(1);
  if (first < 0 || first + T > known_.size(0) || x0.size(2) != known_.size(1))
    throw Error(fmt::format("kept frames: a window [{}, {}) of width {} for {} frames of width {}", first, first + T,
                            x0.size(2), known_.size(0), known_.size(1)));
  const at::Tensor m = weight_.slice(0, first, first + T).unsqueeze(0);  // [1, T, 1]
  const at::Tensor k = known_.slice(0, first, first + T).unsqueeze(0);
  // Exactly the known values where m = 1 (not k·1 + x0·0, which a NaN-free x0 gives too,
  // but rounding could not).
  return at::where(m == 1, k, m * k + (1 - m) * x0.to(at::kFloat)).to(x0.scalar_type());
}

at::Tensor ConstraintChain::impose(const at::Tensor& x0, std::int64_t first, int step, int num_steps) const {
  at::Tensor x = x0;
  for (const auto& c : list_) x = c->impose(x, first, step, num_steps);
  return x;
}

namespace {

Sequence read_kept(const KeptSample& keep, std::int64_t frames) {
  Sequence seq = read_sequence(keep.sample);
  if (seq.num_frames() != frames)
    throw Error(fmt::format("{}: {} frames, but the run's trajectory has {}: redraw a sample with its own trajectory "
                            "(bimart edit does)",
                            keep.sample, seq.num_frames(), frames));
  return seq;
}

}  // namespace

std::shared_ptr<KeptFrames> kept_contact_maps(const KeptSample& keep, std::int64_t frames) {
  const Sequence seq = read_kept(keep, frames);
  if (!seq.contact_maps.defined())
    throw Error(keep.sample + ": holds no contact maps to keep (a sample of bimart run holds them)");
  std::vector<double> w = keep.weights(frames);
  if (keep.keep_contacts) w.assign(w.size(), 1.0);
  return std::make_shared<KeptFrames>(seq.contact_maps.reshape({frames, 2048}), w);
}

std::shared_ptr<KeptFrames> kept_hand_features(const KeptSample& keep, const std::array<const HandModel*, 2>& hands,
                                               const ArticulatedObject& object, const at::Tensor& states) {
  const Sequence seq = read_kept(keep, states.size(0));
  const at::Tensor vertices = seq.hands.has_vertices() ? seq.hands.vertices : pose_hand_vertices(hands, seq.hands);
  const at::Tensor X = hand_features(vertices, model_keypoints(*hands[1]), object, states);
  return std::make_shared<KeptFrames>(X, keep.weights(states.size(0)));
}

}  // namespace bimart
