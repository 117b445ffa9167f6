// Training of the contact and motion diffusion models (DESIGN §5; docs/training.md): Adam
// with a cosine schedule after a linear warm-up, x0-prediction loss weighted by the frame
// mask, EMA weights for sampling, contact-condition dropout for the motion model, periodic
// validation on the test split, atomic checkpoints (at intervals and when stopped), an
// exact resume, and data-parallel training over several processes (c10d with Gloo).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include "core/diffusion/denoiser.h"

namespace bimart {
class WindowDataset;
struct WindowBatch;
struct NormalizationStats;
}  // namespace bimart

namespace bimart::diffusion {

class DataParallel;

struct TrainConfig {
  std::string file;        // where it was read from ("" = built in code)
  std::string text;        // the YAML text, stored in checkpoints
  std::string model = "motion";  // "contact" or "motion"
  std::string data;        // data set folder (core/data/manifest.h)
  std::string out;         // run folder: checkpoint.npz, loss.csv
  std::string export_path; // the sampling model (EMA weights only) written with each checkpoint; "" = none
  bool export_half = false;  // store the export's parameters as float16 (half the file; widened on load)
  // A model to start from instead of random weights (not used on --resume): parameters of
  // the same name and shape are copied; a Linear weight that gained input columns (e.g.
  // the contact cue) keeps the old ones and gets zeros in the new. "" = random start.
  std::string init;
  std::string variant = "np_bps";
  // Motion model: what it samples, "keypoints" (X = [H | D], the method) or "mano" (MANO-Rep,
  // core/diffusion/representation.h). The contact model refuses "mano".
  std::string representation = "keypoints";
  // Motion model: its second condition (core/diffusion/representation.h): "contact" (C, the
  // method), "none" (MDM-B, OMOMO-B's first stage) or "joints" (OMOMO-B's second stage).
  std::string condition = "contact";
  int stride = 16;         // window stride of the training windows
  DenoiserConfig network;
  // Contact model: > 0 samples C in log space, log(C + contact_log_eps) normalised (metres;
  // NormalizationStats::c_log_eps). 0: C itself (the paper's).
  double contact_log_eps = 0;
  // Contact model: > 0 samples C in the K principal directions per hand of the normalised
  // training maps (NormalizationStats::c_basis; a sample of 2K per frame). 0: all 2048.
  int contact_basis = 0;
  // network.global_states: false = the object condition is O alone (3072 per frame), the
  // paper's "w/o G" ablation; true = [O | G] (3079, the method). Sets
  // network.object_condition_size (core/diffusion/object_condition.h).
  bool global_states = true;
  std::string schedule = "squaredcos_cap_v2";
  double schedule_shift = 1;  // diffusion.shift: make_schedule's data scale (1 = none)
  int diffusion_steps = 50;
  int batch = 64;          // windows per step (per process when distributed)
  std::int64_t steps = 10000;
  double lr = 1e-4;
  int warmup = 100;        // linear warm-up steps, then cosine decay to 0 at `steps`
  double weight_decay = 0;
  double grad_clip = 1.0;  // max global gradient norm; 0 = off
  double ema = 0.999;      // EMA decay (warmed up: min(ema, (1 + k) / (10 + k)))
  double contact_dropout = 0.5;  // motion model: P(null contact token) per window
  // Share of each batch whose diffusion step is drawn from [noisy_from, steps) instead of
  // all steps (0 = uniform, the paper). The noisiest steps are where the conditions decide
  // the sample; under uniform steps they get 1/steps of the training each.
  double noisy_share = 0;
  int noisy_from = 35;
  std::uint64_t seed = 1;
  int checkpoint_every = 200;    // steps
  int validate_every = 500;      // steps; 0 = never
  int validation_windows = 256;  // fixed windows of the test split
  int log_every = 20;            // steps between progress lines
};

// Reads a training YAML (docs/training.md). Unknown keys, wrong types and values out of
// range are errors naming the file and line. Relative paths (data, out, export) are taken
// relative to the current folder.
TrainConfig load_train_config(const std::string& path);
// Throws bimart::Error naming the field for a value out of range.
void validate(const TrainConfig& config);

// The learning rate at `step` (0-based): linear warm-up to `lr` over `warmup` steps, then
// cosine decay to 0 at `steps`.
double learning_rate(const TrainConfig& config, std::int64_t step);

struct TrainOptions {
  bool resume = false;             // continue from out/checkpoint.npz
  std::int64_t stop_after = 0;     // stop (with a checkpoint) after this many steps of this call; 0 = run to the end
  std::function<bool()> stop_requested;  // polled each step (signals); true = checkpoint and stop
  bool progress = true;            // log progress lines
  std::shared_ptr<DataParallel> parallel;  // several processes; null = one
  std::map<std::string, at::Tensor>* final_weights = nullptr;  // if set: the raw weights at the end (every rank)
};

struct TrainResult {
  std::int64_t steps_done = 0;     // total optimizer steps in the checkpoint
  bool finished = false;           // reached config.steps
  bool interrupted = false;        // stopped by stop_requested
  double last_loss = 0;            // mean training loss of the last logged interval
  double last_validation = 0;      // NaN when never validated
  double windows_per_second = 0;   // of this call, over all processes
  double seconds = 0;
  std::string checkpoint;          // path written last
};

TrainResult train(const TrainConfig& config, const TrainOptions& options);

// One optimisation target, separated from data loading so that tests (and several
// processes) can feed explicit batches: the loss of a batch with given noise and steps.
struct StepInputs {
  at::Tensor sample;     // [B, T, S] normalised clean sample (C, X or MANO-Rep)
  at::Tensor object;     // [B, T, 3079] normalised [O | G], or [B, T, 3072] O (w/o G)
  at::Tensor contact;    // [B, T, 2048] normalised C (motion model) or undefined
  at::Tensor use_contact;  // [B] bool (motion model) or undefined
  at::Tensor mask;       // [B, T] 1 = real frame
  at::Tensor noise;      // [B, T, S]
  at::Tensor t;          // [B] int64
};
// Copies `weights` into net's parameters of the same name (TrainConfig::init): equal
// shapes as they are; a 2-D weight with more columns here gets the old columns and zeros.
// Others are left as they are, with a warning. Returns the number copied.
int warm_start(torch::nn::Module& net, const std::map<std::string, at::Tensor>& weights);

// What a model denoises, normalised: the contact maps C [B, T, 2048] ("contact"), or for
// "motion" the hand features X [B, T, 1200] (representation "keypoints") or MANO-Rep
// [B, T, 294] ("mano") or the joints [B, T, 96] ("joints") of a batch.
at::Tensor normalized_sample(const std::string& model, const std::string& representation,
                             const NormalizationStats& stats, const WindowBatch& batch);
// A motion model's second condition, normalised: C [B, T, 2048] ("contact"), the joints
// [B, T, 96] ("joints"), or undefined ("none", and for the contact model).
at::Tensor normalized_condition(const std::string& model, const std::string& condition,
                                const NormalizationStats& stats, const WindowBatch& batch);
// Builds StepInputs from a batch: normalisation, and noise, steps and contact dropout
// drawn from `gen`.
StepInputs make_step_inputs(const TrainConfig& config, const NormalizationStats& stats,
                            const WindowBatch& batch, at::Generator gen);
// The inputs of training step `step` on process `rank`: every random draw (the windows,
// noise, steps, contact dropout, and the network's dropout that follows) is seeded from
// (config.seed, step, rank), so a resumed run draws exactly what an uninterrupted one did.
StepInputs draw_step(const TrainConfig& config, const NormalizationStats& stats, const WindowDataset& data,
                     std::int64_t step, int rank);
// Sum over real frames of the per-frame mean squared error of the x0 prediction, and the
// number of real frames: loss = sum / frames.
struct LossParts {
  at::Tensor sum;   // scalar, differentiable
  double frames = 0;
};
LossParts step_loss(Denoiser& net, const struct NoiseSchedule& schedule, const StepInputs& in);

}  // namespace bimart::diffusion
