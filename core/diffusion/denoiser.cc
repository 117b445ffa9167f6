#include "core/diffusion/denoiser.h"

#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/transformerlayer.h>

#include <ATen/core/grad_mode.h>
#include <ATen/ops/_transformer_encoder_layer_fwd.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/diffusion/schedule.h"
#include "core/features/contact_cue.h"
#include "core/util/error.h"

namespace bimart::diffusion {
namespace {

torch::nn::Sequential condition_mlp(int in, int hidden, int out) {
  return torch::nn::Sequential(torch::nn::Linear(in, hidden), torch::nn::ReLU(),
                               torch::nn::Linear(hidden, hidden), torch::nn::ReLU(),
                               torch::nn::Linear(hidden, out));
}

void require(bool ok, const std::string& field, const std::string& what) {
  if (!ok) throw Error("denoiser config: '" + field + "' " + what);
}

}  // namespace

DenoiserConfig DenoiserConfig::paper(const std::string& model) {
  DenoiserConfig c;
  c.model = model;
  if (model == "contact") {
    c.sample_size = 2048;
    c.contact_condition_size = 0;
  } else {
    c.sample_size = 1200;
    c.contact_condition_size = 2048;
  }
  return c;
}

void DenoiserConfig::validate() const {
  require(model == "contact" || model == "motion", "model", "must be contact or motion, got '" + model + "'");
  require(sample_size > 0, "sample_size", "must be positive");
  require(object_condition_size > 0, "object_condition_size", "must be positive");
  require(contact_condition_size >= 0, "contact_condition_size", "must not be negative");
  require(window >= 1 && window <= 4096, "window", "must be in [1, 4096], got " + std::to_string(window));
  require(latent >= 8 && latent <= 8192, "latent", "must be in [8, 8192], got " + std::to_string(latent));
  require(heads >= 1 && latent % heads == 0, "heads",
          "must divide latent (" + std::to_string(latent) + "), got " + std::to_string(heads));
  require(layers >= 1 && layers <= 64, "layers", "must be in [1, 64], got " + std::to_string(layers));
  require(feedforward >= 1, "feedforward", "must be positive");
  require(condition_hidden >= 1, "condition_hidden", "must be positive");
  require(dropout >= 0 && dropout < 1, "dropout", "must be in [0, 1)");
  require(output == "x0" || output == "gaussian" || output == "temporal", "output",
          "must be x0, gaussian or temporal, got '" + output + "'");
  require(skip_rank >= 1 && skip_rank <= 65536, "skip_rank", "must be in [1, 65536]");
  const bool has_object_points =
      model == "motion" && contact_condition_size == 2 * 1024 && object_condition_size == 3079;
  const char* needs = "needs the motion model with contact maps [2, 1024] and object features [1024, 3 | 7]";
  require(!contact_cue || has_object_points, "contact_cue", needs);
  require(contact_points >= 0 && contact_points <= 1024, "contact_points", "must be in [0, 1024]");
  require(contact_points == 0 || has_object_points, "contact_points", needs);
  require(point_hidden >= 1, "point_hidden", "must be positive");
}

std::string DenoiserConfig::describe() const {
  return model + " denoiser: latent " + std::to_string(latent) + ", " + std::to_string(layers) +
         " layers, " + std::to_string(heads) + " heads, feed-forward " + std::to_string(feedforward) +
         ", condition MLPs " + std::to_string(condition_hidden) + ", window " + std::to_string(window) +
         (contact_cue ? ", contact cue" : "") +
         (contact_points > 0 ? ", contact points " + std::to_string(contact_points) + " (MLP " +
                                   std::to_string(point_hidden) + ")"
                             : "") +
         (output != "x0" ? ", " + output + ", Gaussian skip of rank " + std::to_string(std::min(skip_rank, sample_size)) : "");
}

at::Tensor predict_x0(DenoiserImpl& net, const NoiseSchedule& schedule, const at::Tensor& x_t, const at::Tensor& t,
                      const at::Tensor& cond) {
  const at::Tensor out = net.forward(x_t, t, cond);
  if (net.config().output == "x0") return out;
  const at::Tensor abar = at::tensor(schedule.alphas_cumprod, at::kDouble).index_select(0, t.to(at::kLong));
  const at::Tensor a = abar.to(x_t.scalar_type()).view({x_t.size(0), 1, 1});
  const at::Tensor& U = net.skip_directions();
  // Variances per direction ([k], `gaussian`) or per (DCT frequency, direction) ([T, k],
  // `temporal`); a window shorter than the model's uses the per-direction mean (no
  // temporal filtering).
  const int64_t T = x_t.size(1);
  const bool temporal = net.config().output == "temporal" && T == net.config().window;
  at::Tensor v = net.skip_variances();
  v = temporal ? v.unsqueeze(0) : (v.dim() == 2 ? v.mean(0) : v).view({1, 1, -1});  // [1, T or 1, k]
  const at::Tensor den = a * v + (1.0 - a);
  const at::Tensor gain = a.sqrt() * v / den;
  // c_t: the root of the variance the filter leaves, per sample entry.
  const at::Tensor rest = (v * (1.0 - a) / den).sum({1, 2}, true).div(static_cast<double>(v.size(1) * x_t.size(-1))).sqrt();
  at::Tensor z = at::matmul(x_t, U);  // [B, T, k]
  if (temporal) {
    const at::Tensor Q = dct_matrix(T);
    z = at::matmul(Q.t(), at::matmul(Q, z) * gain);
  } else {
    z = z * gain;
  }
  return at::matmul(z, U.t()) + rest * out;
}

at::Tensor dct_matrix(int64_t n) {
  const at::Tensor k = at::arange(n, at::kDouble).unsqueeze(1), t = at::arange(n, at::kDouble).unsqueeze(0);
  at::Tensor q = (M_PI / static_cast<double>(n) * (t + 0.5) * k).cos() * std::sqrt(2.0 / static_cast<double>(n));
  q[0].mul_(std::sqrt(0.5));
  return q.to(at::kFloat);
}

std::pair<at::Tensor, at::Tensor> principal_directions(const at::Tensor& samples, int k) {
  if (samples.dim() != 2 || samples.size(0) < 1)
    throw Error("principal directions: need samples [N, D], got " + c10::str(samples.sizes()));
  const at::Tensor x = samples.to(at::kDouble);
  const at::Tensor moment = at::matmul(x.t(), x) / static_cast<double>(x.size(0));
  const auto [values, vectors] = at::linalg_eigh(moment);  // ascending
  const int64_t D = x.size(1), n = std::min<int64_t>(k, D);
  const at::Tensor top = at::arange(D - 1, D - 1 - n, -1, at::kLong);
  return {vectors.index_select(1, top).to(at::kFloat).contiguous(),
          values.index_select(0, top).clamp_min(0.0).to(at::kFloat).contiguous()};
}

void DenoiserImpl::set_gaussian_skip(const at::Tensor& directions, const at::Tensor& variances) {
  if (!directions.sizes().equals(skip_directions_.sizes()) || !variances.sizes().equals(skip_variances_.sizes()))
    throw Error("denoiser: Gaussian skip must be " + c10::str(skip_directions_.sizes()) + " and " +
                c10::str(skip_variances_.sizes()) + ", got " + c10::str(directions.sizes()) + " and " +
                c10::str(variances.sizes()));
  torch::NoGradGuard ng;
  skip_directions_.copy_(directions);
  skip_variances_.copy_(variances);
}

void DenoiserImpl::set_cue_frame(const at::Tensor& object_mean, const at::Tensor& object_std,
                                 const at::Tensor& contact_mean, const at::Tensor& contact_std,
                                 const at::Tensor& basis_points, bool scaled) {
  if (!reads_object_points()) throw Error("denoiser: set_cue_frame on a model without the contact cue or points");
  const std::vector<std::pair<const at::Tensor*, at::Tensor*>> pairs = {
      {&object_mean, &cue_object_mean_}, {&object_std, &cue_object_std_}, {&contact_mean, &cue_contact_mean_},
      {&contact_std, &cue_contact_std_}, {&basis_points, &cue_basis_}};
  for (const auto& [from, to] : pairs)
    if (!from->sizes().equals(to->sizes()))
      throw Error("denoiser: contact cue frame must be " + c10::str(to->sizes()) + ", got " + c10::str(from->sizes()));
  torch::NoGradGuard ng;
  for (const auto& [from, to] : pairs) to->copy_(*from);
  cue_scaled_.fill_(scaled ? 1.0 : 0.0);
}

DenoiserImpl::ObjectContact DenoiserImpl::object_contact_of(const at::Tensor& object, const at::Tensor& contact) const {
  const auto B = object.size(0), T = object.size(1);
  const at::Tensor obj = object * cue_object_std_ + cue_object_mean_;  // [B, T, 3079]
  const at::Tensor O = obj.slice(2, 0, 3072).reshape({B, T, 1024, 3});
  const at::Tensor s_o = obj.select(2, 3078);                          // G's last entry
  const at::Tensor scale = s_o * cue_scaled_ + (1.0 - cue_scaled_);  // s_o, or 1 for U-BPS
  const at::Tensor C = (contact * cue_contact_std_ + cue_contact_mean_).view({B, T, 2, 1024});
  return {object_points_from_bps(O, cue_basis_, scale), O, C};
}

at::Tensor timestep_embedding(const at::Tensor& t, int dim) {
  const int half = dim / 2;
  const auto freqs =
      torch::exp(-std::log(10000.0) * torch::arange(half, torch::kFloat) / static_cast<double>(half));
  const auto args = t.to(torch::kFloat).unsqueeze(1) * freqs.unsqueeze(0);
  auto emb = torch::cat({torch::sin(args), torch::cos(args)}, 1);
  if (dim % 2 == 1) emb = torch::cat({emb, torch::zeros({t.size(0), 1})}, 1);
  return emb;
}

at::Tensor sinusoidal_positions(int count, int dim) {
  return timestep_embedding(torch::arange(count, torch::kLong), dim);
}

DenoiserImpl::DenoiserImpl(const DenoiserConfig& config) : config_(config) {
  config_.validate();
  const int L = config_.latent;
  input_ = register_module("input", torch::nn::Linear(config_.sample_size, L));
  output_ = register_module("output", torch::nn::Linear(L, config_.sample_size));
  time_mlp_ = register_module(
      "time_mlp", torch::nn::Sequential(torch::nn::Linear(L, L), torch::nn::SiLU(), torch::nn::Linear(L, L)));
  object_mlp_ = register_module("object_mlp", condition_mlp(config_.object_condition_size,
                                                            config_.condition_hidden, L));
  if (config_.contact_condition_size > 0) {
    const int cue = config_.contact_cue ? kContactCueSize : 0;
    contact_mlp_ = register_module("contact_mlp", condition_mlp(config_.contact_condition_size + cue,
                                                                config_.condition_hidden, L));
    null_contact_ = register_parameter("null_contact", torch::randn({config_.window, L}) * 0.02);
  }
  auto layer = torch::nn::TransformerEncoderLayerOptions(L, config_.heads)
                   .dim_feedforward(config_.feedforward)
                   .dropout(config_.dropout)
                   .activation(torch::kGELU);
  encoder_ = register_module(
      "encoder", torch::nn::TransformerEncoder(torch::nn::TransformerEncoderOptions(layer, config_.layers)));
  positions_ = register_buffer("positions", sinusoidal_positions(config_.window + 1, L));
  if (config_.contact_points > 0)
    contact_points_ = register_module("contact_points",
                                      ContactPointEncoder(config_.contact_points, config_.point_hidden, L));
  if (reads_object_points()) {
    cue_object_mean_ = register_buffer("cue_object_mean", torch::zeros({config_.object_condition_size}));
    cue_object_std_ = register_buffer("cue_object_std", torch::ones({config_.object_condition_size}));
    cue_contact_mean_ = register_buffer("cue_contact_mean", torch::zeros({config_.contact_condition_size}));
    cue_contact_std_ = register_buffer("cue_contact_std", torch::ones({config_.contact_condition_size}));
    cue_basis_ = register_buffer("cue_basis", torch::zeros({1024, 3}));
    cue_scaled_ = register_buffer("cue_scaled", torch::ones({1}));
  }
  if (config_.output != "x0") {
    const int k = std::min(config_.skip_rank, config_.sample_size);
    skip_directions_ = register_buffer("skip_directions", torch::eye(config_.sample_size, k));
    skip_variances_ = register_buffer("skip_variances", config_.output == "temporal"
                                                           ? torch::ones({config_.window, k})
                                                           : torch::ones({k}));
  }
}

at::Tensor DenoiserImpl::encode_conditions(const at::Tensor& object, const at::Tensor& contact,
                                           const at::Tensor& use_contact) {
  const auto B = object.size(0), T = object.size(1);
  if (object.dim() != 3 || object.size(2) != config_.object_condition_size) {
    throw Error("denoiser: object condition must be [B, T, " +
                std::to_string(config_.object_condition_size) + "], got " + c10::str(object.sizes()));
  }
  if (T > config_.window) {
    throw Error("denoiser: " + std::to_string(T) + " frames exceed the model's window of " +
                std::to_string(config_.window));
  }
  at::Tensor cond = object_mlp_->forward(object);
  if (config_.contact_condition_size == 0) return cond;
  const at::Tensor null = null_contact_.slice(0, 0, T).unsqueeze(0).expand({B, T, config_.latent});
  if (!contact.defined()) return cond + null;
  if (contact.dim() != 3 || contact.size(0) != B || contact.size(1) != T ||
      contact.size(2) != config_.contact_condition_size) {
    throw Error("denoiser: contact condition must be [" + std::to_string(B) + ", " + std::to_string(T) +
                ", " + std::to_string(config_.contact_condition_size) + "], got " + c10::str(contact.sizes()));
  }
  const ObjectContact in = reads_object_points() ? object_contact_of(object, contact) : ObjectContact{};
  at::Tensor c = contact_mlp_->forward(
      config_.contact_cue ? torch::cat({contact, contact_cue(in.points, in.maps)}, -1) : contact);
  if (contact_points_) c = c + contact_points_->forward(in.points, in.offsets, in.maps);
  if (!use_contact.defined()) return cond + c;
  const at::Tensor keep = use_contact.to(torch::kBool).view({B, 1, 1});
  return cond + torch::where(keep, c, null);
}

at::Tensor DenoiserImpl::forward(const at::Tensor& x_t, const at::Tensor& t, const at::Tensor& cond) {
  const auto B = x_t.size(0), T = x_t.size(1);
  if (x_t.dim() != 3 || x_t.size(2) != config_.sample_size) {
    throw Error("denoiser: sample must be [B, T, " + std::to_string(config_.sample_size) + "], got " +
                c10::str(x_t.sizes()));
  }
  if (cond.size(0) != B || cond.size(1) != T) {
    throw Error("denoiser: conditions " + c10::str(cond.sizes()) + " do not match the sample " +
                c10::str(x_t.sizes()));
  }
  const at::Tensor frames = input_->forward(x_t) + cond;                         // [B, T, L]
  const at::Tensor step = time_mlp_->forward(timestep_embedding(t, config_.latent)).unsqueeze(1);
  const at::Tensor tokens = torch::cat({step, frames}, 1) + positions_.slice(0, 0, T + 1).unsqueeze(0);
  // Sampling (no autograd, eval mode) runs each layer as ATen's fused encoder-layer kernel
  // (the one PyTorch's Python fast path calls): fewer ops per layer, 3-7 % faster at the
  // default size (the rest is GEMM, docs/performance.md). Training uses the module.
  const bool fused = !is_training() && !at::GradMode::is_enabled();
  // libtorch's encoder module takes [sequence, batch, latent]; the fused kernel batch first.
  const at::Tensor encoded = fused ? encode_fused(tokens) : encoder_->forward(tokens.transpose(0, 1)).transpose(0, 1);
  return output_->forward(encoded.slice(1, 1, T + 1));
}

at::Tensor DenoiserImpl::encode_fused(const at::Tensor& tokens) const {
  at::Tensor x = tokens;
  for (const auto& module : *encoder_->layers) {
    const auto& layer = module->as<torch::nn::TransformerEncoderLayerImpl>();
    const auto& attention = *layer->self_attn;
    x = at::_transformer_encoder_layer_fwd(
        x, config_.latent, config_.heads, attention.in_proj_weight, attention.in_proj_bias,
        attention.out_proj->weight, attention.out_proj->bias, /*use_gelu=*/true, /*norm_first=*/false,
        layer->norm1->options.eps(), layer->norm1->weight, layer->norm1->bias, layer->norm2->weight,
        layer->norm2->bias, layer->linear1->weight, layer->linear1->bias, layer->linear2->weight,
        layer->linear2->bias);
  }
  return x;
}

std::int64_t DenoiserImpl::num_parameters() const {
  std::int64_t n = 0;
  for (const auto& p : parameters()) n += p.numel();
  return n;
}

}  // namespace bimart::diffusion
