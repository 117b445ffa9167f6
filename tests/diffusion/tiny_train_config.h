// A training config of a tiny denoiser (latent 16, one layer, two heads) on the tiny data
// set (tests/data/tiny_dataset.h), batch 3, a checkpoint every 3 steps: the part the
// training tests share. Each test sets its own steps, rate, validation and seed.
#pragma once

#include <filesystem>
#include <string>

#include "core/diffusion/training.h"
#include "tests/data/tiny_dataset.h"

namespace bimart::diffusion {

inline TrainConfig tiny_train_config(const std::filesystem::path& out, const std::string& model) {
  TrainConfig c;
  c.model = model;
  c.data = testing_data::tiny_dataset().dir.string();
  c.out = out.string();
  c.network = DenoiserConfig::paper(model);
  c.network.latent = 16;
  c.network.layers = 1;
  c.network.heads = 2;
  c.network.feedforward = 32;
  c.network.condition_hidden = 16;
  c.batch = 3;
  c.checkpoint_every = 3;
  return c;
}

}  // namespace bimart::diffusion
