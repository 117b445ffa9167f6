#include "core/io/sequence.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include <ATen/ATen.h>

#include "core/geometry/point_guard.h"
#include "core/io/npz.h"
#include "core/util/error.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHandPrefix[2] = {"left_", "right_"};
constexpr int kFormatVersion = 1;

// A float32 contiguous CPU copy (callers may hand in doubles or views).
at::Tensor as_f32(const at::Tensor& t) { return t.detach().to(at::kCPU, at::kFloat).contiguous(); }

// Where element `flat` of a tensor sits, e.g. "frame 3 [0]" or "left hand, frame 3 [5, 2]";
// `frame_dim` is the axis of the frames (-1: none).
std::string element_place(const at::Tensor& t, int64_t flat, int frame_dim) {
  std::vector<int64_t> idx(static_cast<size_t>(t.dim()));
  for (int64_t d = t.dim() - 1; d >= 0; --d) {
    idx[static_cast<size_t>(d)] = flat % t.size(d);
    flat /= t.size(d);
  }
  std::string place, rest;
  for (int64_t d = 0; d < t.dim(); ++d) {
    const int64_t i = idx[static_cast<size_t>(d)];
    if (d == frame_dim) place += (place.empty() ? "" : ", ") + ("frame " + std::to_string(i));
    else if (frame_dim == 1 && d == 0) place += i == 0 ? "left hand" : "right hand";
    else rest += (rest.empty() ? "" : ", ") + std::to_string(i);
  }
  return place + (rest.empty() ? "" : " [" + rest + "]");
}

// Shape, then every value finite and within `bound` (DESIGN §8: a clear error naming the
// field, frame and component, never a crash further down). bound <= 0: finite only.
void check_tensor(const at::Tensor& t, const std::string& field, const std::vector<int64_t>& shape,
                  const std::string& where, double bound = kMaxPoseValue, const char* unit = "",
                  int frame_dim = 0) {
  const std::string at_ = where.empty() ? "" : where + ": ";
  if (!t.defined()) throw Error(at_ + "sequence field '" + field + "' is missing");
  bool ok = t.dim() == static_cast<int64_t>(shape.size());
  for (size_t i = 0; ok && i < shape.size(); ++i) ok = shape[i] < 0 || t.size(int64_t(i)) == shape[i];
  if (!ok) {
    std::string want = "[";
    for (size_t i = 0; i < shape.size(); ++i)
      want += (i ? ", " : "") + (shape[i] < 0 ? std::string("*") : std::to_string(shape[i]));
    want += "]";
    std::string got = "[";
    for (int64_t i = 0; i < t.dim(); ++i) got += (i ? ", " : "") + std::to_string(t.size(i));
    got += "]";
    throw Error(at_ + "sequence field '" + field + "' has shape " + got + ", expected " + want);
  }
  if (t.numel() == 0) return;
  const at::Tensor d = t.detach().to(at::kCPU, at::kDouble).contiguous();
  const double* v = d.data_ptr<double>();
  const long bad = first_out_of_bounds(v, static_cast<long>(d.numel()), bound > 0 ? bound : HUGE_VAL);
  if (bad < 0) return;
  const std::string place = element_place(d, bad, shape.size() == 1 ? -1 : frame_dim);
  if (!std::isfinite(v[bad]))
    throw Error(at_ + "sequence field '" + field + "', " + place + ": value " + fmt::format("{}", v[bad]) +
                " is not finite");
  throw Error(at_ + "sequence field '" + field + "', " + place + ": value " + fmt::format("{:g}", v[bad]) +
              " is beyond the bound ±" + fmt::format("{:g}", bound) + unit +
              " (docs/formats.md, \"Sequence\")");
}

void validate_at(const Sequence& s, const std::string& where) {
  const std::string at_ = where.empty() ? "" : where + ": ";
  if (!(std::isfinite(s.fps) && s.fps > 0))
    throw Error(at_ + "sequence field 'fps' must be a positive number, got " + std::to_string(s.fps));
  if (s.object.empty()) throw Error(at_ + "sequence field 'object' (the object path) is empty");
  check_tensor(s.object_states, "object_states", {-1, 7}, where, kMaxPoseValue, " (rad or m)");
  const int64_t n = s.object_states.size(0);
  if (n < 1) throw Error(at_ + "sequence has no frames ('object_states' is empty)");
  if (n > kMaxFrames)
    throw Error(at_ + "sequence has " + std::to_string(n) + " frames, more than the " + std::to_string(kMaxFrames) +
                " bimart handles");
  for (int h = 0; h < 2; ++h) {
    const std::string p = kHandPrefix[h];
    const HandParams& hp = s.hands.hands[static_cast<size_t>(h)];
    check_tensor(hp.rot, p + "rot", {n, 3}, where, kMaxPoseValue, " rad");
    check_tensor(hp.pose, p + "pose", {n, 45}, where, kMaxPoseValue, " rad");
    check_tensor(hp.trans, p + "trans", {n, 3}, where, kMaxPoseValue, " m");
    check_tensor(hp.shape, p + "shape", {10}, where, kMaxPoseValue);
  }
  if (s.hands.has_vertices())
    check_tensor(s.hands.vertices, "hand_vertices", {2, n, -1, 3}, where, kMaxPoseValue, " m", 1);
  if (s.contact_maps.defined() != s.basis_hit_indices.defined())
    throw Error(at_ + "sequence fields 'contact_maps' and 'basis_hit_indices' come together");
  if (s.contact_maps.defined()) {
    check_tensor(s.contact_maps, "contact_maps", {n, 2, -1}, where, kMaxPoseValue, " m");
    check_tensor(s.basis_hit_indices, "basis_hit_indices", {n, s.contact_maps.size(2)}, where, 0);
  }
}

NpyArray tensor_npy(const at::Tensor& t) {
  const at::Tensor f = as_f32(t);
  return make_npy(f.data_ptr<float>(), std::vector<int64_t>(f.sizes().begin(), f.sizes().end()));
}

at::Tensor npy_tensor(const NpzFile& npz, const std::string& key) {
  const NpyArray& a = npz.get(key);
  const std::vector<float> v = as_vector<float>(a, npz.where(key));
  return at::from_blob(const_cast<float*>(v.data()), std::vector<int64_t>(a.shape.begin(), a.shape.end()),
                       at::kFloat)
      .clone();
}

std::string read_string(const NpzFile& npz, const std::string& key, bool required) {
  if (!npz.contains(key)) {
    if (required) npz.get(key);  // throws naming the file, the key and the keys present
    return "";
  }
  const std::vector<std::string> s = as_strings(npz.get(key), npz.where(key));
  if (s.size() != 1) throw Error(npz.where(key) + " must hold one string");
  return s[0];
}

}  // namespace

void Sequence::validate() const { validate_at(*this, name.empty() ? "" : "sequence '" + name + "'"); }

Sequence read_sequence(const std::string& path) {
  const NpzFile npz = NpzFile::read(path);
  Sequence s;
  if (npz.contains("format_version")) {
    const auto v = npz.vector<int64_t>("format_version");
    if (v.size() != 1 || v[0] > kFormatVersion)
      throw Error(npz.where("format_version") + ": unsupported sequence format version (this "
                  "program reads up to " + std::to_string(kFormatVersion) + ")");
  }
  s.object = read_string(npz, "object", true);
  s.name = read_string(npz, "name", false);
  if (s.name.empty()) s.name = fs::path(path).stem().string();
  s.category = read_string(npz, "category", false);
  s.kind = read_string(npz, "kind", false);
  const auto fps = npz.vector<double>("fps");
  if (fps.size() != 1) throw Error(npz.where("fps") + " must be one number");
  s.fps = fps[0];
  s.object_states = npy_tensor(npz, "object_states");
  for (int h = 0; h < 2; ++h) {
    const std::string p = kHandPrefix[h];
    HandParams& hp = s.hands.hands[static_cast<size_t>(h)];
    hp.rot = npy_tensor(npz, p + "rot");
    hp.pose = npy_tensor(npz, p + "pose");
    hp.trans = npy_tensor(npz, p + "trans");
    hp.shape = npy_tensor(npz, p + "shape");
  }
  if (npz.contains("hand_vertices")) s.hands.vertices = npy_tensor(npz, "hand_vertices");
  if (npz.contains("contact_maps")) s.contact_maps = npy_tensor(npz, "contact_maps");
  if (npz.contains("basis_hit_indices")) {
    const NpyArray& a = npz.get("basis_hit_indices");
    std::vector<int64_t> v = as_vector<int64_t>(a, npz.where("basis_hit_indices"));
    s.basis_hit_indices =
        at::from_blob(v.data(), std::vector<int64_t>(a.shape.begin(), a.shape.end()), at::kLong).clone();
  }
  validate_at(s, path);
  return s;
}

void write_sequence(const Sequence& s, const std::string& path) {
  validate_at(s, path);
  NpzFile npz;
  npz.set("format_version", make_npy_scalar<int64_t>(kFormatVersion));
  npz.set("name", make_npy_strings({s.name}, {}));
  npz.set("object", make_npy_strings({s.object}, {}));
  npz.set("category", make_npy_strings({s.category}, {}));
  npz.set("kind", make_npy_strings({s.kind}, {}));
  npz.set("fps", make_npy_scalar<double>(s.fps));
  npz.set("object_states", tensor_npy(s.object_states));
  for (int h = 0; h < 2; ++h) {
    const std::string p = kHandPrefix[h];
    const HandParams& hp = s.hands.hands[static_cast<size_t>(h)];
    npz.set(p + "rot", tensor_npy(hp.rot));
    npz.set(p + "pose", tensor_npy(hp.pose));
    npz.set(p + "trans", tensor_npy(hp.trans));
    npz.set(p + "shape", tensor_npy(hp.shape));
  }
  if (s.hands.has_vertices()) npz.set("hand_vertices", tensor_npy(s.hands.vertices));
  if (s.contact_maps.defined()) {
    npz.set("contact_maps", tensor_npy(s.contact_maps));
    const at::Tensor idx = s.basis_hit_indices.to(at::kCPU, at::kLong).contiguous();
    npz.set("basis_hit_indices",
            make_npy(idx.data_ptr<int64_t>(), std::vector<int64_t>(idx.sizes().begin(), idx.sizes().end())));
  }
  npz.write(path);  // atomic (NpzFile::write)
}

std::string relative_object_path(const std::string& object_path, const std::string& sequence_path) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::absolute(fs::path(sequence_path)).parent_path();
  const fs::path object = fs::absolute(object_path).lexically_normal();
  const fs::path rel = fs::relative(object, folder);
  // Near the file (a data set's ../objects/x): relative, so the folders move together.
  // Farther (an object cache in the home folder): absolute, so copying the file keeps it.
  int ups = 0;
  for (const auto& part : rel) ups += part == "..";
  return rel.empty() || ups > 2 ? object.string() : rel.string();
}

std::string resolve_object_path(const Sequence& sequence, const std::string& sequence_path) {
  const fs::path obj(sequence.object);
  if (obj.is_absolute()) return obj.lexically_normal().string();
  return (fs::path(sequence_path).parent_path() / obj).lexically_normal().string();
}

}  // namespace bimart
