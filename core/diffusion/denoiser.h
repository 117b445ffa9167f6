// The denoisers of both diffusion models (DESIGN §5): a transformer encoder over the frames
// of a window, with the diffusion step as an extra first token (sinusoidal embedding +
// MLP), sinusoidal positions, one linear layer in and one out, and per-frame condition
// MLPs whose outputs are added to the frame tokens: the object condition [O | G] for both
// models, and for the motion model the contact maps C or a learned per-frame null token.
// The model predicts the clean sample x0 (normalised).
//
// The condition MLPs do not depend on the step or the noisy sample, so they are encoded
// once per sampling (encode_conditions) and reused by every denoising step (forward).
#pragma once

#include <cstdint>
#include <string>

#include <torch/nn/module.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/transformercoder.h>

namespace bimart::diffusion {

struct DenoiserConfig {
  std::string model = "motion";    // "contact" (sample C) or "motion" (sample X, conditioned on C)
  int sample_size = 1200;          // per frame: 2048 (C) or 1200 (X)
  int object_condition_size = 3079;  // [O | G]
  int contact_condition_size = 0;  // 2048 for the motion model, 0 for the contact model
  int window = 64;                 // frames per window (positions, null tokens)
  int latent = 512;
  int layers = 8;
  int heads = 4;
  int feedforward = 1024;
  int condition_hidden = 1024;     // width of the condition MLPs (input -> h -> h -> latent)
  double dropout = 0.1;

  // The configuration of a model kind with the paper's size (DESIGN §5).
  static DenoiserConfig paper(const std::string& model);
  // Throws bimart::Error naming the field for a value out of range.
  void validate() const;
  // "latent 256, 4 layers, ..." for logs.
  std::string describe() const;
};

class DenoiserImpl : public torch::nn::Module {
 public:
  explicit DenoiserImpl(const DenoiserConfig& config);

  // Per-frame condition tokens [B, T, latent]: object_mlp(object) plus, for the motion
  // model, contact_mlp(contact) where `use_contact[b]` is true and the null token of each
  // frame where it is false. object [B, T, 3079]; contact [B, T, 2048] (may be undefined
  // when use_contact is all false, or for the contact model); use_contact [B] bool
  // (undefined = all true when contact is given, all false otherwise).
  at::Tensor encode_conditions(const at::Tensor& object, const at::Tensor& contact = {},
                               const at::Tensor& use_contact = {});

  // x0 prediction [B, T, sample]: x_t [B, T, sample], t [B] int64 steps, cond [B, T, latent].
  at::Tensor forward(const at::Tensor& x_t, const at::Tensor& t, const at::Tensor& cond);

  const DenoiserConfig& config() const { return config_; }
  std::int64_t num_parameters() const;

 private:
  DenoiserConfig config_;
  torch::nn::Linear input_{nullptr}, output_{nullptr};
  torch::nn::Sequential time_mlp_{nullptr}, object_mlp_{nullptr}, contact_mlp_{nullptr};
  torch::nn::TransformerEncoder encoder_{nullptr};
  at::Tensor null_contact_;  // [window, latent] parameter (motion model)
  at::Tensor positions_;     // [window + 1, latent] buffer: sinusoidal positions
};
TORCH_MODULE(Denoiser);

// Sinusoidal embedding [B, dim] of the steps t [B] (transformer style: sin then cos over
// log-spaced frequencies from 1 to 1/10000).
at::Tensor timestep_embedding(const at::Tensor& t, int dim);
// Sinusoidal positions [count, dim].
at::Tensor sinusoidal_positions(int count, int dim);

}  // namespace bimart::diffusion
