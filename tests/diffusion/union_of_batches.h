// The reference a data-parallel training is checked against: one process that trains on
// the union of the batches `world` ranks draw at each step (each rank seeds its draws with
// its rank), with train()'s data, normalisation, schedule, initialisation and optimiser.
// Used by training_test.cc (ranks on threads) and slurm_test.cc (ranks as srun tasks).
// Needs dropout 0 and grad_clip 0 (dropout masks and the clipping norm depend on how the
// batch is split), x0 output and no contact cue, basis or initial model.
#pragma once

#include <torch/optim/adam.h>

#include <ATen/ATen.h>

#include <algorithm>
#include <vector>

#include "core/data/normalization.h"
#include "core/data/window_dataset.h"
#include "core/diffusion/checkpoint.h"
#include "core/diffusion/representation.h"
#include "core/diffusion/schedule.h"
#include "core/diffusion/training.h"

namespace bimart::diffusion {

inline TensorMap train_on_union_of_batches(const TrainConfig& c, int world) {
  WindowDatasetOptions wo;
  wo.variant = parse_bps_variant(c.variant);
  wo.stride = c.stride;
  wo.mano = c.representation == kManoRepresentation;
  const WindowDataset data = WindowDataset::open(c.data, "train", wo);
  const NormalizationStats stats = compute_normalization(data, kNormalizationStdFloor, c.contact_log_eps);
  const NoiseSchedule schedule = make_schedule(c.schedule, c.diffusion_steps, c.schedule_shift);
  torch::manual_seed(c.seed);
  Denoiser net(c.network);
  torch::optim::Adam opt(net->parameters(), torch::optim::AdamOptions(c.lr).weight_decay(c.weight_decay));
  for (std::int64_t step = 0; step < c.steps; ++step) {
    std::vector<StepInputs> parts;
    for (int r = 0; r < world; ++r) parts.push_back(draw_step(c, stats, data, step, r));
    const auto cat = [&](at::Tensor StepInputs::*member) {
      std::vector<at::Tensor> ts;
      for (const auto& p : parts) ts.push_back(p.*member);
      return at::cat(ts);
    };
    StepInputs u;
    u.sample = cat(&StepInputs::sample);
    u.object = cat(&StepInputs::object);
    u.contact = cat(&StepInputs::contact);
    u.use_contact = cat(&StepInputs::use_contact);
    u.mask = cat(&StepInputs::mask);
    u.noise = cat(&StepInputs::noise);
    u.t = cat(&StepInputs::t);
    const LossParts lp = step_loss(net, schedule, u);
    opt.zero_grad();
    (lp.sum / lp.frames).backward();
    for (auto& p : net->parameters())  // as train(): unused parameters get a zero gradient
      if (!p.grad().defined()) p.mutable_grad() = at::zeros_like(p);
    for (auto& g : opt.param_groups())
      static_cast<torch::optim::AdamOptions&>(g.options()).lr(learning_rate(c, step));
    opt.step();
  }
  return state_of(*net);
}

// The largest absolute difference between parameters of the same name (every parameter
// of `a` must be in `b`).
inline double largest_parameter_difference(const TensorMap& a, const TensorMap& b) {
  double worst = 0;
  for (const auto& [k, v] : a) worst = std::max(worst, (v - b.at(k)).abs().max().item<double>());
  return worst;
}

}  // namespace bimart::diffusion
