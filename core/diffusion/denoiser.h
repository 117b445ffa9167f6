// The denoisers of both diffusion models (DESIGN §5): a transformer encoder over the frames
// of a window, with the diffusion step as an extra first token (sinusoidal embedding +
// MLP), sinusoidal positions, one linear layer in and one out, and per-frame condition
// MLPs whose outputs are added to the frame tokens: the object condition [O | G] for both
// models, and for the motion model the contact maps C or a learned per-frame null token.
// The model predicts the clean sample x0 (normalised), either as the network's output
// ("x0") or as the best linear estimate from the noisy input plus the network's correction
// ("gaussian", see DenoiserConfig::output and predict_x0).
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

#include "core/diffusion/contact_point_encoder.h"

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
  // "x0": the network's output F is the x0 prediction. "gaussian": x0 = S_t·x_t + c_t·F,
  // where S_t is the optimal (Wiener) denoiser of Gaussian data with the training samples'
  // covariance U·diag(λ)·Uᵀ (its top `skip_rank` directions, fitted before training):
  // S_t = U·diag(√ᾱ λ / (ᾱ λ + 1 − ᾱ))·Uᵀ, and c_t² = Σ λ(1 − ᾱ)/(ᾱ λ + 1 − ᾱ) / D its mean
  // remaining variance (Karras et al. 2022's c_skip/c_out with a covariance instead of one
  // σ_data). At low noise x0 is then x_t projected onto the data, at high noise the
  // network's. S_t filters each frame alone, so the noise it lets through is white over
  // time and samples flicker. "temporal": the same filter in the basis DCT over the
  // window's frames × U, with one variance per (frequency, direction) — smooth samples
  // (docs/training.md, "Output"). Both experimental; the shipped models are "x0".
  std::string output = "x0";
  int skip_rank = 256;  // directions of S_t (at most sample_size)
  // Motion model: the contact MLP also reads the contact cue of C (core/features/contact_cue.h),
  // computed inside encode_conditions from the normalised inputs with the frame set by
  // set_cue_frame (stored with the weights).
  bool contact_cue = false;
  // Motion model: K > 0 adds the contact point encoder (core/diffusion/contact_point_encoder.h)
  // over each hand's K nearest object points, with a point MLP `point_hidden` wide; its
  // token is added to the contact MLP's. Uses the same frame as the cue (set_cue_frame).
  int contact_points = 0;
  int point_hidden = 128;

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

  // The network's output [B, T, sample] (x0 or F, see DenoiserConfig::output; predict_x0
  // gives x0 for both): x_t [B, T, sample], t [B] int64 steps, cond [B, T, latent].
  at::Tensor forward(const at::Tensor& x_t, const at::Tensor& t, const at::Tensor& cond);

  const DenoiserConfig& config() const { return config_; }
  // Whether encode_conditions needs the object points, i.e. set_cue_frame (contact cue or points).
  bool reads_object_points() const { return config_.contact_cue || config_.contact_points > 0; }
  // The skip's directions U [sample, k] (orthonormal columns) and variances λ: [k], or
  // [window, k] per DCT frequency for "temporal" (buffers, stored with the weights). Until
  // set: the first k unit vectors, λ = 1.
  void set_gaussian_skip(const at::Tensor& directions, const at::Tensor& variances);
  // What the contact cue needs to undo the normalisation of its inputs: the object
  // condition's and the contact maps' mean and std ([3079], [2048]), the basis points
  // [1024, 3], and whether encoder space is scaled by s_o (false for U-BPS).
  void set_cue_frame(const at::Tensor& object_mean, const at::Tensor& object_std, const at::Tensor& contact_mean,
                     const at::Tensor& contact_std, const at::Tensor& basis_points, bool scaled);
  const at::Tensor& skip_directions() const { return skip_directions_; }
  const at::Tensor& skip_variances() const { return skip_variances_; }
  std::int64_t num_parameters() const;

 private:
  DenoiserConfig config_;
  torch::nn::Linear input_{nullptr}, output_{nullptr};
  torch::nn::Sequential time_mlp_{nullptr}, object_mlp_{nullptr}, contact_mlp_{nullptr};
  torch::nn::TransformerEncoder encoder_{nullptr};
  ContactPointEncoder contact_points_{nullptr};
  at::Tensor null_contact_;  // [window, latent] parameter (motion model)
  at::Tensor positions_;     // [window + 1, latent] buffer: sinusoidal positions
  at::Tensor skip_directions_, skip_variances_;  // "gaussian" output: [sample, k], [k] buffers
  // contact cue or points: buffers object mean/std [3079], contact mean/std [2048], basis
  // [1024, 3], scaled [1] (1 = divide by s_o).
  at::Tensor cue_object_mean_, cue_object_std_, cue_contact_mean_, cue_contact_std_, cue_basis_, cue_scaled_;
  at::Tensor encode_fused(const at::Tensor& tokens) const;  // the encoder, no autograd: [B, T+1, L]
  // The un-normalised inputs: object points [B, T, 1024, 3] (m), BPS offsets [B, T, 1024, 3]
  // and contact maps [B, T, 2, 1024] (m) of normalised object / contact conditions.
  struct ObjectContact {
    at::Tensor points, offsets, maps;
  };
  ObjectContact object_contact_of(const at::Tensor& object, const at::Tensor& contact) const;
};
TORCH_MODULE(Denoiser);

struct NoiseSchedule;
// The x0 prediction of `net` (either output kind): x_t, t, cond as for forward.
at::Tensor predict_x0(DenoiserImpl& net, const NoiseSchedule& schedule, const at::Tensor& x_t, const at::Tensor& t,
                      const at::Tensor& cond);
// The top k eigenvectors [D, k] and eigenvalues [k] (descending) of the second moment
// XᵀX / N of samples X [N, D] (normalised data: mean ≈ 0), for set_gaussian_skip.
std::pair<at::Tensor, at::Tensor> principal_directions(const at::Tensor& samples, int k);
// The orthonormal DCT-II matrix [n, n] (row k = frequency k).
at::Tensor dct_matrix(int64_t n);

// Sinusoidal embedding [B, dim] of the steps t [B] (transformer style: sin then cos over
// log-spaced frequencies from 1 to 1/10000).
at::Tensor timestep_embedding(const at::Tensor& t, int dim);
// Sinusoidal positions [count, dim].
at::Tensor sinusoidal_positions(int count, int dim);

}  // namespace bimart::diffusion
