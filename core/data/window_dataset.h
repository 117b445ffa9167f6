// Training windows for both diffusion models (DESIGN §4, §5; docs/data_loader.md): the
// sequences of one split of a data set, cut into windows of W = 64 frames, with the
// features every model reads — O (BPS object features), G (global states), C (contact maps
// from the hand meshes), X (hand features [H | D]) and the basis hit indices — and, on
// request, the MANO representation of the hands (core/features/mano_representation.h).
//
// Features are computed once per sequence (never per window), sequences in parallel, and
// kept compactly in memory: O, C and X as float16, hit indices as int16, frames with the
// same hinge angle share one row of O and of the hit indices, and basis rows that never
// change within a sequence are stored once. A batch is assembled by
// copying its windows' frames and converting them back to float32 / int64. With a data
// set folder the per-sequence features are also cached on disk under
// FOLDER/cache/<variant>/ and recomputed when the sequence (or its object) changed.
//
// Windows start every `stride` frames (default 16); the last window of a sequence is
// aligned to its end. A sequence shorter than W gives one window padded by repeating its
// last frame; `mask` marks the real frames (1) and the padding (0).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/features/bps.h"

namespace bimart {

constexpr int kWindowFrames = 64;  // DESIGN §5: the window (horizon)
constexpr int kBasisRows = 1024;   // rows of O, C and the hit indices per frame

// "np_bps", "npa_bps", "u_bps" (the encoder plug-ins' names without "encoder.").
std::string bps_variant_name(BpsVariant variant);
// The inverse; throws bimart::Error listing the known names.
BpsVariant parse_bps_variant(const std::string& name);

struct WindowDatasetOptions {
  BpsVariant variant = BpsVariant::PerPart;  // NP-BPS, the method
  // The basis file; "" = the variant's shipped file (default_basis_file, core/util/data_path.h).
  std::string basis_file;
  int window = kWindowFrames;
  int stride = 16;
  // O, C, X as float16 (|error| <= 2^-11 |x| + 2^-25, docs/data_loader.md); false: float32.
  bool half_precision = true;
  // Also the MANO representation of each sequence's hands (MANO-Rep motion models), from
  // its MANO parameters posed with the posing hand models (core/metrics/hand_vertices.h).
  bool mano = false;
  // Per-sequence feature cache on disk (WindowDataset::open only, unless cache_dir is set).
  bool cache = true;
  std::string cache_dir;  // "" = FOLDER/cache/<variant>
  // Sequences processed at once, on plain threads that each run libtorch single-threaded;
  // 0 = libtorch's intra-op thread count (--threads).
  int threads = 0;
  // Called after each sequence with (done, total); calls are serialised but may come from
  // worker threads, and must not throw.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// A batch of B windows, float32 unless noted, frames in the window's order.
struct WindowBatch {
  at::Tensor object_features;  // O [B, W, 1024, 3], encoder space (DESIGN §4)
  at::Tensor global_states;    // G [B, W, 7]: root axis-angle, root translation minus that of
                               //   the window's first frame, s_o
  at::Tensor contact_maps;     // C [B, W, 2, 1024], metres, left hand first
  at::Tensor hand_features;    // X [B, W, 1200], canonical frame, [H_l, H_r, D_l, D_r]
  at::Tensor mano;             // MANO-Rep [B, W, 294], canonical frame; undefined unless the data set holds it
  at::Tensor hit_indices;      // [B, W, 1024] int64 into the object's [top; bottom] vertices
  at::Tensor mask;             // [B, W]: 1 for a frame of the sequence, 0 for padding
  at::Tensor object_states;    // [B, W, 7] the raw 7-DoF states (padding repeats the last)
  at::Tensor sequence;         // [B] int64: index into WindowDataset::sequences()
  at::Tensor start;            // [B] int64: the window's first frame in its sequence
};

// One sequence's features, compact. O and the hit indices depend on the hinge angle only,
// so frames with the same angle share one row (frame f: row feature_row[f]); and basis rows
// that are the same in every frame of the sequence (for NP-BPS the whole bottom half) are
// stored once in the templates, the others (`dynamic_rows`) per row.
struct DatasetSequence {
  std::string path;  // the sequence file
  std::string name, category, kind;
  std::string object_path;  // resolved (core/io/sequence.h, resolve_object_path)
  double fps = 30;
  double scale = 1;                // s_o
  std::int64_t frames = 0;         // N
  at::Tensor states;               // [N, 7] float32
  at::Tensor feature_row;          // [N] int32, in [0, U)
  at::Tensor object_template;      // [1024, 3] float16 (float32 without half_precision): row 0's O
  at::Tensor hit_template;         // [1024] int16 (int32 for objects of >= 32768 vertices)
  at::Tensor dynamic_rows;         // [D] int32: the basis rows that change, ascending
  at::Tensor object_features;      // [U, D, 3] O of the dynamic rows
  at::Tensor hit_indices;          // [U, D]
  at::Tensor contact_maps;         // [N, 2, 1024] float16 / float32
  at::Tensor hand_features;        // [N, 1200] float16 / float32
  at::Tensor mano;                 // [N, 294] float16 / float32 MANO-Rep, or undefined (WindowDatasetOptions::mano)
  std::size_t bytes() const;       // memory held by the tensors above
  at::Tensor object_rows() const;  // [U, 1024, 3] float32: every basis row, rebuilt
  at::Tensor hit_rows() const;     // [U, 1024] int64
};

struct WindowRef {
  std::int32_t sequence = 0;  // index into sequences()
  std::int32_t start = 0;     // first frame
};

struct WindowDatasetLoadReport {
  std::size_t computed = 0;  // sequences whose features were computed
  std::size_t cached = 0;    // sequences read from the cache
  double seconds = 0;        // wall time of the whole load
};

class WindowDataset {
 public:
  // The sequences of `split` ("train" or "test") of the data set FOLDER (core/data/manifest.h).
  static WindowDataset open(const std::string& folder, const std::string& split,
                            const WindowDatasetOptions& options = {});
  // Explicit sequence files (no manifest); cached only when options.cache_dir is set.
  static WindowDataset from_files(const std::vector<std::string>& files, const WindowDatasetOptions& options = {});

  std::size_t size() const { return windows_.size(); }  // windows
  const std::vector<WindowRef>& windows() const { return windows_; }
  const std::vector<DatasetSequence>& sequences() const { return sequences_; }
  std::int64_t num_frames() const;   // frames of all sequences (without padding)
  std::size_t memory_bytes() const;  // all sequences' features
  int window() const { return window_; }
  int stride() const { return stride_; }
  BpsVariant variant() const { return variant_; }
  const BpsBasis& basis() const { return basis_; }
  const std::string& basis_file() const { return basis_file_; }
  at::Tensor basis_points() const;  // [1024, 3] float32, as ObjectEncoding::basis_points
  const WindowDatasetLoadReport& load_report() const { return report_; }

  // The windows `indices` (each in [0, size())), stacked. Deterministic.
  WindowBatch batch(const std::vector<std::int64_t>& indices) const;
  // B windows drawn uniformly: distinct when B <= size(), with repetition otherwise. The
  // draw uses only rng's raw output (no std distributions), so a seed gives the same batch
  // on every platform.
  WindowBatch sample_batch(std::int64_t batch_size, std::mt19937_64& rng) const;
  // min(count, size()) window indices spread evenly (i · size() / count): a fixed subset,
  // the same for every run, for validation and checks.
  std::vector<std::int64_t> spread(std::int64_t count) const;
  // All window indices in a random order (Fisher-Yates with rng's raw output): an epoch.
  std::vector<std::int64_t> shuffled(std::mt19937_64& rng) const;

 private:
  WindowDataset() = default;
  static WindowDataset load(const std::vector<std::string>& files, const std::string& cache_base,
                            const std::string& cache_dir, const WindowDatasetOptions& options);

  std::vector<DatasetSequence> sequences_;
  std::vector<WindowRef> windows_;
  int window_ = kWindowFrames;
  int stride_ = 16;
  BpsVariant variant_ = BpsVariant::PerPart;
  BpsBasis basis_;
  std::string basis_file_;
  WindowDatasetLoadReport report_;
};

// The window starts of a sequence of `frames` frames: 0, stride, 2·stride, ... while the
// window fits, then frames - window when the last one does not end at the last frame; {0}
// when frames <= window.
std::vector<std::int32_t> window_starts(std::int64_t frames, int window, int stride);

}  // namespace bimart
