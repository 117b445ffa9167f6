// A kept sample (core/directing/hand_constraints.h, KeptSample) imposed on sampling:
// x0 ← m · known + (1 − m) · x0 per frame, m the sample's weights (1 outside the redrawn
// stretch, ramping to 0 inside it), known the sample's contact maps (contact model) or its
// hand features X (motion model). So the kept frames come out exactly as they were and the
// stretch is drawn by the model, joined to them as overlapping windows are.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/directing/hand_constraints.h"
#include "core/hand/hand_model.h"
#include "core/object/articulated_object.h"
#include "stages/sample_constraint.h"

namespace bimart {

class KeptFrames : public SampleConstraint {
 public:
  // known [N, D] (model units), weights N values in [0, 1].
  KeptFrames(at::Tensor known, const std::vector<double>& weights);
  at::Tensor impose(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const override;

 private:
  at::Tensor known_;   // [N, D] float32
  at::Tensor weight_;  // [N, 1] float32
};

// Constraints applied one after the other (null entries skipped).
class ConstraintChain : public SampleConstraint {
 public:
  void add(std::shared_ptr<const SampleConstraint> c) {
    if (c) list_.push_back(std::move(c));
  }
  bool empty() const { return list_.empty(); }
  at::Tensor impose(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const override;

 private:
  std::vector<std::shared_ptr<const SampleConstraint>> list_;
};

// The kept sample's contact maps [N, 2048] (its frames must match the run's N), for the
// contact model; weights all 1 with keep_contacts. Throws naming the file when it has none.
std::shared_ptr<KeptFrames> kept_contact_maps(const KeptSample& keep, std::int64_t frames);

// Its hand features X [N, 1200] (hand_features of its hands posed by `hands`), for the
// motion model.
std::shared_ptr<KeptFrames> kept_hand_features(const KeptSample& keep, const std::array<const HandModel*, 2>& hands,
                                               const ArticulatedObject& object, const at::Tensor& states);

}  // namespace bimart
