#include "core/data/normalization.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/data/window_dataset.h"
#include "core/features/hand_features.h"
#include "core/features/mano_representation.h"
#include "core/io/npz.h"
#include "core/util/error.h"

namespace bimart {
namespace {

constexpr int kFormatVersion = 1;
constexpr int kObjectRow = kBasisRows * 3;

std::string shape_str(const at::Tensor& t) { return t.defined() ? std::string(c10::str(t.sizes())) : "undefined"; }

// Weighted count, mean and sum of squared deviations per feature, float64. Plain loops on
// one thread: libtorch's intra-op parallelism on these small tensors spends more time in
// OpenMP barriers than in arithmetic on a loaded machine (docs/data_loader.md).
struct Moments {
  double weight = 0;
  std::vector<double> mean, m2;
};

// Rows r of x (R x F, row-major, float16 or float32) with weights w[r]; two passes.
template <class T>
Moments moments(const T* x, int64_t rows, int64_t features, const double* w) {
  Moments m;
  for (int64_t r = 0; r < rows; ++r) m.weight += w[r];
  if (m.weight <= 0) return m;
  m.mean.assign(static_cast<std::size_t>(features), 0.0);
  m.m2.assign(static_cast<std::size_t>(features), 0.0);
  double* mean = m.mean.data();
  double* m2 = m.m2.data();
  for (int64_t r = 0; r < rows; ++r) {
    if (w[r] == 0) continue;
    const T* row = x + r * features;
    for (int64_t f = 0; f < features; ++f) mean[f] += w[r] * static_cast<double>(row[f]);
  }
  for (int64_t f = 0; f < features; ++f) mean[f] /= m.weight;
  for (int64_t r = 0; r < rows; ++r) {
    if (w[r] == 0) continue;
    const T* row = x + r * features;
    for (int64_t f = 0; f < features; ++f) {
      const double d = static_cast<double>(row[f]) - mean[f];
      m2[f] += w[r] * d * d;
    }
  }
  return m;
}

Moments moments_of(const at::Tensor& t, int64_t rows, int64_t features, const double* w) {
  if (t.scalar_type() == at::kHalf) return moments(t.data_ptr<at::Half>(), rows, features, w);
  if (t.scalar_type() == at::kFloat) return moments(t.data_ptr<float>(), rows, features, w);
  const at::Tensor d = t.to(at::kDouble).contiguous();
  return moments(d.data_ptr<double>(), rows, features, w);
}

// Chan et al.'s pairwise update: `acc` becomes the moments of both sets.
void combine(Moments& acc, const Moments& p) {
  if (p.weight <= 0) return;
  if (acc.weight <= 0) {
    acc = p;
    return;
  }
  const double total = acc.weight + p.weight, a = p.weight / total, b = acc.weight * p.weight / total;
  for (std::size_t f = 0; f < acc.mean.size(); ++f) {
    const double delta = p.mean[f] - acc.mean[f];
    acc.mean[f] += delta * a;
    acc.m2[f] += p.m2[f] + delta * delta * b;
  }
  acc.weight = total;
}

at::Tensor mean_of(const Moments& m) { return at::tensor(m.mean, at::kDouble); }

at::Tensor floored_std(const Moments& m, double floor) {
  std::vector<double> s(m.m2.size());
  for (std::size_t f = 0; f < s.size(); ++f) s[f] = std::max(std::sqrt(m.m2[f] / m.weight), floor);
  return at::tensor(s, at::kDouble);
}

void check_last_dim(const at::Tensor& x, const at::Tensor& mean, const at::Tensor& std, const char* what) {
  if (!x.defined() || x.dim() < 1) throw Error(std::string(what) + ": need a tensor [..., F], got " + shape_str(x));
  if (!mean.defined() || !std.defined() || mean.dim() != 1 || !std.sizes().equals(mean.sizes()) ||
      x.size(-1) != mean.size(0))
    throw Error(std::string(what) + ": tensor " + shape_str(x) + " does not match the statistics " + shape_str(mean) +
                " (last dimension)");
}

NpyArray npy_of(const at::Tensor& t) {
  const at::Tensor d = t.to(at::kDouble).contiguous();
  return make_npy(d.data_ptr<double>(), {d.size(0)});
}

// Window starts of `train`, by sequence (windows() is ordered by sequence).
std::vector<std::vector<std::int32_t>> windows_by_sequence(const WindowDataset& train) {
  std::vector<std::vector<std::int32_t>> starts(train.sequences().size());
  for (const WindowRef& r : train.windows()) starts[static_cast<std::size_t>(r.sequence)].push_back(r.start);
  return starts;
}

// Frame weights of one sequence: the windows (starting at `starts`, `window` frames long)
// each frame appears in as a real (not padded) frame.
std::vector<double> frame_weights(const std::vector<std::int32_t>& starts, int window, int64_t frames) {
  std::vector<double> weight(static_cast<std::size_t>(frames), 0.0);
  for (std::int32_t start : starts)
    for (int64_t f = start; f < std::min<int64_t>(start + window, frames); ++f) weight[static_cast<std::size_t>(f)] += 1;
  return weight;
}

// A float64 array of `shape` (-1: any extent) from f[key], every value finite (and > 0
// when `positive`); throws naming the key.
at::Tensor read_array(const NpzFile& f, const std::string& key, const std::vector<int64_t>& shape, bool positive) {
  const NpyArray& a = f.get(key, shape);
  const std::vector<double> v = as_vector<double>(a, f.where(key));
  for (double x : v)
    if (!std::isfinite(x) || (positive && !(x > 0)))
      throw Error(f.where(key) + ": holds " + std::to_string(x) +
                  (positive ? " (must be positive and finite)" : " (not finite)"));
  return at::tensor(v, at::kDouble).view(a.shape);
}

at::Tensor read_vector(const NpzFile& f, const std::string& key, int64_t size, bool positive) {
  return read_array(f, key, {size}, positive);
}

}  // namespace

at::Tensor object_condition(const at::Tensor& object_features, const at::Tensor& global_states) {
  const at::Tensor& o = object_features;
  const at::Tensor& g = global_states;
  if (!o.defined() || o.dim() < 2 || o.size(-1) != 3 || o.size(-2) != kBasisRows || !g.defined() ||
      g.dim() != o.dim() - 1 || g.size(-1) != 7 ||
      !o.sizes().slice(0, o.dim() - 2).equals(g.sizes().slice(0, g.dim() - 1)))
    throw Error("object condition: need O [..., 1024, 3] and G [..., 7] with the same leading dimensions, got " +
                shape_str(o) + " and " + shape_str(g));
  return at::cat({o.flatten(-2), g.to(o.scalar_type())}, -1);
}

at::Tensor normalize(const at::Tensor& x, const at::Tensor& mean, const at::Tensor& std) {
  check_last_dim(x, mean, std, "normalize");
  return (x - mean.to(x.scalar_type())) / std.to(x.scalar_type());
}

at::Tensor denormalize(const at::Tensor& x, const at::Tensor& mean, const at::Tensor& std) {
  check_last_dim(x, mean, std, "denormalize");
  return x * std.to(x.scalar_type()) + mean.to(x.scalar_type());
}

at::Tensor NormalizationStats::normalize_x(const at::Tensor& x) const { return normalize(x, x_mean, x_std); }
at::Tensor NormalizationStats::denormalize_x(const at::Tensor& x) const { return denormalize(x, x_mean, x_std); }

at::Tensor NormalizationStats::normalize_mano(const at::Tensor& m) const {
  if (!mano_mean.defined()) throw Error("normalize_mano: these statistics hold no MANO representation");
  return normalize(m, mano_mean, mano_std);
}
at::Tensor NormalizationStats::denormalize_mano(const at::Tensor& m) const {
  if (!mano_mean.defined()) throw Error("denormalize_mano: these statistics hold no MANO representation");
  return denormalize(m, mano_mean, mano_std);
}

at::Tensor NormalizationStats::normalize_joints(const at::Tensor& j) const {
  if (!mano_mean.defined()) throw Error("normalize_joints: these statistics hold no MANO representation");
  const at::Tensor c = at::tensor(mano_representation_joint_columns(), at::kLong);
  return normalize(j, mano_mean.index_select(0, c), mano_std.index_select(0, c));
}
at::Tensor NormalizationStats::denormalize_joints(const at::Tensor& j) const {
  if (!mano_mean.defined()) throw Error("denormalize_joints: these statistics hold no MANO representation");
  const at::Tensor c = at::tensor(mano_representation_joint_columns(), at::kLong);
  return denormalize(j, mano_mean.index_select(0, c), mano_std.index_select(0, c));
}

at::Tensor NormalizationStats::normalize_object(const at::Tensor& object_features,
                                                const at::Tensor& global_states) const {
  return normalize(object_condition(object_features, global_states), obj_mean, obj_std);
}

namespace {
// C as the statistics see it: log(C + eps) when eps > 0, else C.
at::Tensor contact_space(const at::Tensor& c, double eps) { return eps > 0 ? at::log(c.clamp_min(0) + eps) : c; }
}  // namespace

at::Tensor NormalizationStats::normalize_c(const at::Tensor& c) const {
  if (!c.defined() || c.dim() < 2 || c.size(-2) != 2 || c.size(-1) != kBasisRows)
    throw Error("normalize_c: contact maps must be [..., 2, 1024], got " + shape_str(c));
  return normalize(contact_space(c, c_log_eps).flatten(-2), c_mean, c_std).view(c.sizes());
}

at::Tensor NormalizationStats::denormalize_c(const at::Tensor& c) const {
  if (!c.defined() || c.dim() < 2 || c.size(-2) != 2 || c.size(-1) != kBasisRows)
    throw Error("denormalize_c: contact maps must be [..., 2, 1024], got " + shape_str(c));
  const at::Tensor v = denormalize(c.flatten(-2), c_mean, c_std).view(c.sizes());
  return c_log_eps > 0 ? at::exp(v) - c_log_eps : v;
}

at::Tensor NormalizationStats::contact_sample(const at::Tensor& c) const {
  const at::Tensor z = normalize_c(c);  // [..., 2, 1024]
  if (!c_basis.defined()) return z.flatten(-2);
  return at::matmul(z, c_basis.to(z.scalar_type())).flatten(-2);
}

std::int64_t NormalizationStats::contact_sample_size() const {
  return c_basis.defined() ? 2 * c_basis.size(1) : 2 * kBasisRows;
}

at::Tensor NormalizationStats::contact_from_sample(const at::Tensor& z) const {
  const std::int64_t D = contact_sample_size();
  if (!z.defined() || z.dim() < 1 || z.size(-1) != D)
    throw Error("contact_from_sample: need a contact sample [..., " + std::to_string(D) + "], got " + shape_str(z));
  std::vector<std::int64_t> shape(z.sizes().begin(), z.sizes().end() - 1);
  shape.push_back(2);
  shape.push_back(D / 2);
  at::Tensor v = z.reshape(shape);
  if (c_basis.defined()) v = at::matmul(v, c_basis.to(z.scalar_type()).t());
  return denormalize_c(v);
}

at::Tensor contact_basis(const WindowDataset& train, const NormalizationStats& stats, int k) {
  if (k < 1 || k > kBasisRows)
    throw Error("contact basis: the number of directions must be in [1, 1024], got " + std::to_string(k));
  if (train.size() == 0) throw Error("contact basis: need at least one window");
  at::NoGradGuard no_grad;
  const auto& seqs = train.sequences();
  const std::vector<std::vector<std::int32_t>> starts = windows_by_sequence(train);
  const int w = train.window();
  // principal_directions (core/diffusion/denoiser.h) does this for samples held in memory;
  // a data set's maps (~1 GB) are accumulated instead. Σ_frames weight · z zᵀ over both
  // hands' normalised maps z; their weighted mean is 0 per
  // entry (the statistics' own weighting), so this is the covariance up to the total weight.
  at::Tensor second = at::zeros({kBasisRows, kBasisRows}, at::kDouble);
  double total = 0;
  for (std::size_t i = 0; i < seqs.size(); ++i) {
    const DatasetSequence& s = seqs[i];
    const at::Tensor wt =
        at::tensor(frame_weights(starts[i], w, s.frames), at::kDouble).to(at::kFloat).repeat_interleave(2);  // [frames · 2]
    const at::Tensor z =
        stats.normalize_c(s.contact_maps.to(at::kFloat).reshape({s.frames, 2, kBasisRows})).reshape({-1, kBasisRows});
    second += at::mm((z * wt.unsqueeze(1)).t(), z).to(at::kDouble);
    total += wt.sum().item<double>();
  }
  if (!(total > 0)) throw Error("contact basis: the windows hold no frames");
  const auto eig = at::linalg_eigh(second / total);                  // ascending eigenvalues
  const at::Tensor basis = std::get<1>(eig).flip({1}).slice(1, 0, k);  // decreasing variance
  const at::Tensor big = basis.abs().argmax(0, true);                   // [1, k]
  return (basis * basis.gather(0, big).sign()).contiguous();            // largest entry positive
}

NormalizationStats compute_normalization(const WindowDataset& train, double std_floor, double c_log_eps) {
  if (train.size() == 0) throw Error("normalisation statistics need at least one window");
  if (!(c_log_eps >= 0) || !std::isfinite(c_log_eps))
    throw Error("normalisation: the contact maps' log epsilon must be >= 0, got " + std::to_string(c_log_eps));
  if (!(std_floor > 0) || !std::isfinite(std_floor))
    throw Error("normalisation: the std floor must be positive, got " + std::to_string(std_floor));
  at::NoGradGuard no_grad;
  const auto& seqs = train.sequences();
  const int64_t n = static_cast<int64_t>(seqs.size());
  const int w = train.window();

  const std::vector<std::vector<std::int32_t>> starts = windows_by_sequence(train);

  struct Partial {
    Moments x, o, c, g, m;
  };
  // MANO-Rep statistics when every sequence holds it.
  bool mano = true;
  for (const DatasetSequence& s : seqs) mano = mano && s.mano.defined();
  // One sequence after the other, combined in sequence order.
  Partial all;
  {
    for (int64_t i = 0; i < n; ++i) {
      const DatasetSequence& s = seqs[static_cast<std::size_t>(i)];
      const int64_t frames = s.frames;
      const std::vector<double> weight = frame_weights(starts[static_cast<std::size_t>(i)], w, frames);
      std::vector<double> g_rows;
      const float* S = s.states.data_ptr<float>();
      for (std::int32_t start : starts[static_cast<std::size_t>(i)]) {
        const float* first = S + 7 * start;
        for (int64_t f = start; f < std::min<int64_t>(start + w, frames); ++f) {
          const float* st = S + 7 * f;
          for (int c = 0; c < 3; ++c) g_rows.push_back(st[1 + c]);
          // The same float32 arithmetic as WindowDataset::batch.
          for (int c = 0; c < 3; ++c)
            g_rows.push_back(static_cast<float>(static_cast<double>(st[4 + c]) - static_cast<double>(first[4 + c])));
          g_rows.push_back(static_cast<float>(s.scale));
        }
      }
      Partial p;
      p.x = moments_of(s.hand_features, frames, kHandFeatureSize, weight.data());
      if (mano) p.m = moments_of(s.mano, frames, kManoRepSize, weight.data());
      const at::Tensor c = c_log_eps > 0 ? contact_space(s.contact_maps.to(at::kFloat), c_log_eps).contiguous()
                                         : s.contact_maps;
      p.c = moments_of(c, frames, 2 * kBasisRows, weight.data());
      const int64_t rows = s.object_features.size(0);
      std::vector<double> row_weight(static_cast<std::size_t>(rows), 0.0);  // frames sharing an O row
      const int32_t* row_of = s.feature_row.data_ptr<int32_t>();
      for (int64_t f = 0; f < frames; ++f)
        row_weight[static_cast<std::size_t>(row_of[f])] += weight[static_cast<std::size_t>(f)];
      p.o = moments_of(s.object_rows(), rows, kObjectRow, row_weight.data());
      const int64_t g_count = static_cast<int64_t>(g_rows.size() / 7);
      const std::vector<double> ones(static_cast<std::size_t>(g_count), 1.0);
      p.g = moments(g_rows.data(), g_count, 7, ones.data());
      combine(all.x, p.x);
      combine(all.c, p.c);
      combine(all.o, p.o);
      combine(all.g, p.g);
      combine(all.m, p.m);
    }
  }
  if (all.x.weight <= 0) throw Error("normalisation statistics: the windows hold no frames");

  NormalizationStats st;
  st.variant = bps_variant_name(train.variant());
  st.count = static_cast<std::int64_t>(std::llround(all.x.weight));
  st.std_floor = std_floor;
  st.c_log_eps = c_log_eps;
  st.x_mean = mean_of(all.x);
  st.x_std = floored_std(all.x, std_floor);
  st.c_mean = mean_of(all.c);
  st.c_std = floored_std(all.c, std_floor);
  if (mano) {
    st.mano_mean = mean_of(all.m);
    st.mano_std = floored_std(all.m, std_floor);
  }
  st.obj_mean = at::cat({mean_of(all.o), mean_of(all.g)});
  st.obj_std = at::cat({floored_std(all.o, std_floor), floored_std(all.g, std_floor)});
  return st;
}

void store_normalization(const NormalizationStats& stats, NpzFile& f, const std::string& prefix) {
  const std::pair<const at::Tensor*, int64_t> checks[] = {
      {&stats.x_mean, kHandFeatureSize},      {&stats.x_std, kHandFeatureSize}, {&stats.obj_mean, kObjectConditionSize},
      {&stats.obj_std, kObjectConditionSize}, {&stats.c_mean, 2 * kBasisRows},  {&stats.c_std, 2 * kBasisRows}};
  for (const auto& [t, size] : checks)
    if (!t->defined() || t->dim() != 1 || t->size(0) != size)
      throw Error("normalisation statistics have a vector of shape " + shape_str(*t) + ", expected [" +
                  std::to_string(size) + "]");
  f.set(prefix + "format_version", make_npy_scalar<std::int64_t>(kFormatVersion));
  f.set(prefix + "variant", make_npy_strings({stats.variant}, {}));
  f.set(prefix + "count", make_npy_scalar<std::int64_t>(stats.count));
  f.set(prefix + "std_floor", make_npy_scalar<double>(stats.std_floor));
  if (stats.c_log_eps > 0) f.set(prefix + "c_log_eps", make_npy_scalar<double>(stats.c_log_eps));
  f.set(prefix + "x_mean", npy_of(stats.x_mean));
  f.set(prefix + "x_std", npy_of(stats.x_std));
  f.set(prefix + "obj_mean", npy_of(stats.obj_mean));
  f.set(prefix + "obj_std", npy_of(stats.obj_std));
  f.set(prefix + "c_mean", npy_of(stats.c_mean));
  f.set(prefix + "c_std", npy_of(stats.c_std));
  if (stats.mano_mean.defined()) {
    if (stats.mano_mean.dim() != 1 || stats.mano_mean.size(0) != kManoRepSize || !stats.mano_std.defined() ||
        !stats.mano_std.sizes().equals(stats.mano_mean.sizes()))
      throw Error("normalisation statistics have MANO-Rep vectors of shape " + shape_str(stats.mano_mean) + " and " +
                  shape_str(stats.mano_std) + ", expected [" + std::to_string(kManoRepSize) + "]");
    f.set(prefix + "mano_mean", npy_of(stats.mano_mean));
    f.set(prefix + "mano_std", npy_of(stats.mano_std));
  }
  if (stats.c_basis.defined()) {
    const at::Tensor b = stats.c_basis.to(at::kDouble).contiguous();
    if (b.dim() != 2 || b.size(0) != kBasisRows || b.size(1) < 1 || b.size(1) > kBasisRows)
      throw Error("normalisation statistics have a contact basis of shape " + shape_str(b) + ", expected [1024, K]");
    f.set(prefix + "c_basis", make_npy(b.data_ptr<double>(), {b.size(0), b.size(1)}));
  }
}

NormalizationStats read_normalization(const NpzFile& f, const std::string& prefix) {
  const std::string version = prefix + "format_version";
  if (f.contains(version)) {
    const auto v = f.vector<std::int64_t>(version);
    if (v.size() != 1 || v[0] > kFormatVersion)
      throw Error(f.where(version) + ": unsupported normalisation file version (this program reads up to " +
                  std::to_string(kFormatVersion) + ")");
  }
  NormalizationStats st;
  const std::vector<std::string> variant = as_strings(f.get(prefix + "variant"), f.where(prefix + "variant"));
  if (variant.size() != 1) throw Error(f.where(prefix + "variant") + " must hold one string");
  st.variant = variant[0];
  const auto count = f.vector<std::int64_t>(prefix + "count");
  if (count.size() != 1 || count[0] < 1) throw Error(f.where(prefix + "count") + " must be one positive number");
  st.count = count[0];
  if (f.contains(prefix + "std_floor")) st.std_floor = f.vector<double>(prefix + "std_floor").at(0);
  if (f.contains(prefix + "c_log_eps")) st.c_log_eps = f.vector<double>(prefix + "c_log_eps").at(0);
  if (!(st.c_log_eps >= 0) || !std::isfinite(st.c_log_eps))
    throw Error(f.where(prefix + "c_log_eps") + " must be a number >= 0");
  st.x_mean = read_vector(f, prefix + "x_mean", kHandFeatureSize, false);
  st.x_std = read_vector(f, prefix + "x_std", kHandFeatureSize, true);
  st.obj_mean = read_vector(f, prefix + "obj_mean", kObjectConditionSize, false);
  st.obj_std = read_vector(f, prefix + "obj_std", kObjectConditionSize, true);
  st.c_mean = read_vector(f, prefix + "c_mean", 2 * kBasisRows, false);
  st.c_std = read_vector(f, prefix + "c_std", 2 * kBasisRows, true);
  if (f.contains(prefix + "mano_mean") || f.contains(prefix + "mano_std")) {
    st.mano_mean = read_vector(f, prefix + "mano_mean", kManoRepSize, false);
    st.mano_std = read_vector(f, prefix + "mano_std", kManoRepSize, true);
  }
  if (f.contains(prefix + "c_basis")) {
    const std::string key = prefix + "c_basis";
    st.c_basis = read_array(f, key, {kBasisRows, -1}, false);
    if (st.c_basis.size(1) < 1 || st.c_basis.size(1) > kBasisRows)
      throw Error(f.where(key) + " must have 1 to 1024 columns");
  }
  return st;
}

void save_normalization(const NormalizationStats& stats, const std::string& path) {
  NpzFile f;
  try {
    store_normalization(stats, f, "");
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  f.write(path);
}

NormalizationStats load_normalization(const std::string& path) { return read_normalization(NpzFile::read(path), ""); }

}  // namespace bimart
