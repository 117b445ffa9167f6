#include "core/data/window_dataset.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "core/data/manifest.h"
#include "core/features/contact_map.h"
#include "core/features/hand_features.h"
#include "core/features/mano_representation.h"
#include "core/hand/hand_model.h"
#include "core/hand/keypoints.h"
#include "core/io/sequence.h"
#include "core/metrics/hand_vertices.h"
#include "core/object/canonical_frame.h"
#include "core/object/object_io.h"
#include "core/util/atomic_file.h"
#include "core/util/data_path.h"
#include "core/util/error.h"
#include "core/util/fingerprint.h"
#include "core/util/log.h"
#include "core/util/text.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr int kObjectRow = kBasisRows * 3;         // O numbers per frame
constexpr int kContactRow = 2 * kBasisRows;        // C numbers per frame
constexpr const char kCacheMagic[9] = "BMFEAT01";  // 8 bytes, then the header length
constexpr int kCacheVersion = 2;  // 2: objects in their canonical pose about the hinge

std::int64_t mtime_of(const fs::path& p) {
  std::error_code ec;
  const auto t = fs::last_write_time(p, ec);
  return ec ? 0 : static_cast<std::int64_t>(t.time_since_epoch().count());
}

// The newest modification time of the files an object path stands for: the file itself
// and the regular files of its folder (object.yaml with its meshes, or a template folder).
std::int64_t object_stamp(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  const fs::path dir = fs::is_directory(p, ec) ? p : p.parent_path();
  std::int64_t newest = mtime_of(p);
  for (const auto& e : fs::directory_iterator(dir.empty() ? fs::path(".") : dir, ec))
    if (e.is_regular_file(ec)) newest = std::max(newest, mtime_of(e.path()));
  return newest;
}

// The hand keypoint ids (HandModel::keypoints of the models hand_vertices poses with, as
// the metrics use) and a fingerprint of those files, which pose the hands of files without
// vertices. One entry per pair of files (set_posing_hand_models may change them).
struct HandInfo {
  std::vector<int> keypoints;
  std::string fingerprint;
  std::array<HandModel, 2> models;  // for the MANO representation's joints
  std::array<const HandModel*, 2> pointers() const { return {&models[0], &models[1]}; }
};

const HandInfo& hand_info() {
  static std::mutex mutex;
  static std::map<std::array<std::string, 2>, std::unique_ptr<HandInfo>> infos;
  const std::array<std::string, 2> files = posing_hand_model_files();
  std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<HandInfo>& slot = infos[files];
  if (!slot) {
    auto info = std::make_unique<HandInfo>();
    Fnv f;
    std::vector<int> ids[2];
    for (int h = 0; h < 2; ++h) {
      const std::string& path = files[h];
      const HandModel& model = info->models[static_cast<std::size_t>(h)] = load_hand_model(path);
      try {
        ids[h] = model_keypoints(model);
      } catch (const Error& e) {
        throw Error(path + ": " + e.message());
      }
      std::error_code ec;
      f.add(fs::absolute(path).string());
      f.add_value(static_cast<std::uint64_t>(fs::file_size(path, ec)));
      f.add_value(mtime_of(path));
    }
    if (ids[0] != ids[1])
      throw Error("the left and right hand models have different keypoint ids; hand features need the same J = " +
                  std::to_string(kHandKeypoints) + " ids on both sides");
    f.add(ids[0].data(), ids[0].size() * sizeof(int));
    info->keypoints = ids[0];
    info->fingerprint = f.hex();
    slot = std::move(info);
  }
  return *slot;
}

std::string basis_fingerprint(const BpsBasis& b) {
  Fnv f;
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> p = b.points;
  f.add(p.data(), static_cast<std::size_t>(p.size()) * sizeof(double));
  f.add_value(b.radius);
  f.add_value(b.seed);
  return f.hex();
}

// Objects by resolved path, each loaded once, moved to its canonical pose about the hinge
// (core/object/canonical_frame.h: what the models see, however the object is turned in its
// files) and shared by the worker threads.
class ObjectStore {
 public:
  std::shared_ptr<const CanonicalObject> get(const std::string& path) {
    std::shared_ptr<Slot> slot;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto& s = slots_[path];
      if (!s) s = std::make_shared<Slot>();
      slot = s;
    }
    std::call_once(slot->once, [&] { slot->object = std::make_shared<CanonicalObject>(to_canonical(load_object(path))); });
    return slot->object;
  }

 private:
  struct Slot {
    std::once_flag once;
    std::shared_ptr<const CanonicalObject> object;
  };
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Slot>> slots_;
};

// What the features of one sequence depend on, besides the sequence file and its object.
struct Inputs {
  BpsVariant variant;
  const BpsBasis* basis;
  std::string basis_fingerprint;
  bool half;
  bool mano;
};

DatasetSequence compute_sequence(const std::string& path, ObjectStore& objects, const Inputs& in) {
  at::NoGradGuard no_grad;
  const Sequence seq = read_sequence(path);
  DatasetSequence d;
  d.path = path;
  d.name = seq.name;
  d.category = seq.category;
  d.kind = seq.kind;
  d.fps = seq.fps;
  d.object_path = resolve_object_path(seq, path);
  d.frames = seq.num_frames();
  const std::shared_ptr<const CanonicalObject> canonical = objects.get(d.object_path);
  const ArticulatedObject* object = &canonical->object;
  const at::Tensor states =
      (canonical->moved ? canonical_states(seq.object_states, canonical->from_source) : seq.object_states)
          .to(at::kCPU, at::kFloat)
          .contiguous();
  const int64_t n = d.frames;

  const ObjectEncoding enc = encode_object(*object, states, *in.basis, in.variant);
  d.scale = enc.scale;
  const at::Tensor hv = hand_vertices(seq.hands);  // [2, N, V, 3] world
  const std::vector<int>& ids = hand_info().keypoints;
  const int max_id = *std::max_element(ids.begin(), ids.end());
  if (hv.size(2) <= max_id)
    throw Error("hand_vertices has " + std::to_string(hv.size(2)) +
                " vertices per hand; the hand model's keypoints need " + std::to_string(max_id + 1) +
                " (store full meshes, or no vertices so that the hands are posed)");
  const at::Tensor X = hand_features(hv, ids, *object, states);
  const at::Tensor C = world_contact_maps(*object, states, enc.hit_indices, hv).to(at::kFloat);

  // Frames with the same hinge angle have the same O and hit indices: one row each.
  std::vector<int64_t> first_frame;
  std::unordered_map<std::uint32_t, int32_t> row_of_angle;
  d.feature_row = at::empty({n}, at::kInt);
  const float* S = states.data_ptr<float>();
  int32_t* rows = d.feature_row.data_ptr<int32_t>();
  for (int64_t t = 0; t < n; ++t) {
    std::uint32_t bits;
    std::memcpy(&bits, S + 7 * t, sizeof bits);
    auto [it, fresh] = row_of_angle.emplace(bits, static_cast<int32_t>(first_frame.size()));
    if (fresh) first_frame.push_back(t);
    rows[t] = it->second;
  }
  const at::Tensor pick = at::tensor(first_frame, at::kLong);
  const at::ScalarType store = in.half ? at::kHalf : at::kFloat;
  const int64_t vertices = object->top.num_vertices() + object->bottom.num_vertices();
  const at::ScalarType hit_type = vertices <= 32767 ? at::kShort : at::kInt;
  const at::Tensor o_rows = enc.features.index_select(0, pick);     // [U, 1024, 3]
  const at::Tensor h_rows = enc.hit_indices.index_select(0, pick);  // [U, 1024]
  // Basis rows with the same vector and hit in every row (exact float32 equality).
  const at::Tensor same = o_rows.eq(o_rows[0]).all(2).all(0).logical_and(h_rows.eq(h_rows[0]).all(0));
  const at::Tensor dynamic = same.logical_not().nonzero().squeeze(1);  // [D] int64, ascending
  d.states = states;
  d.object_template = o_rows[0].to(store).contiguous();
  d.hit_template = h_rows[0].to(hit_type).contiguous();
  d.dynamic_rows = dynamic.to(at::kInt).contiguous();
  d.object_features = o_rows.index_select(1, dynamic).to(store).contiguous();
  d.hit_indices = h_rows.index_select(1, dynamic).to(hit_type).contiguous();
  d.contact_maps = C.to(store).contiguous();
  d.hand_features = X.to(store).contiguous();
  if (in.mano) d.mano = mano_representation(hand_info().pointers(), seq.hands, states).to(store).contiguous();
  return d;
}

// ---- the on-disk cache: "BMFEAT01", u64 header length, JSON header, raw tensors ----------

struct SourceStamp {
  std::uint64_t size = 0;
  std::int64_t mtime = 0;
};

SourceStamp stamp_of(const std::string& path) {
  std::error_code ec;
  SourceStamp s;
  s.size = static_cast<std::uint64_t>(fs::file_size(path, ec));
  s.mtime = mtime_of(path);
  return s;
}

json cache_header(const DatasetSequence& d, const Inputs& in, const SourceStamp& src, std::int64_t object_mtime) {
  return {{"cache_version", kCacheVersion},
          {"variant", bps_variant_name(in.variant)},
          {"storage", in.half ? "f2" : "f4"},
          {"basis", in.basis_fingerprint},
          {"hands", hand_info().fingerprint},
          {"source_size", src.size},
          {"source_mtime", src.mtime},
          {"object_mtime", object_mtime},
          {"name", d.name},
          {"category", d.category},
          {"kind", d.kind},
          {"object", d.object_path},
          {"fps", d.fps},
          {"scale", d.scale},
          {"frames", d.frames},
          {"rows", d.object_features.size(0)},
          {"dynamic_rows", d.dynamic_rows.size(0)},
          {"hit_dtype", d.hit_template.scalar_type() == at::kShort ? "i2" : "i4"},
          {"mano", d.mano.defined()}};  // the MANO representation follows the other tensors
}

std::vector<const at::Tensor*> cache_tensors(const DatasetSequence& d) {
  std::vector<const at::Tensor*> t{&d.states,          &d.feature_row, &d.object_template,
                                   &d.hit_template,    &d.dynamic_rows, &d.object_features,
                                   &d.hit_indices,     &d.contact_maps, &d.hand_features};
  if (d.mano.defined()) t.push_back(&d.mano);
  return t;
}

void write_cache(const std::string& file, const DatasetSequence& d, const Inputs& in, const SourceStamp& src) {
  const std::string header = cache_header(d, in, src, object_stamp(d.object_path)).dump();
  write_file_atomically(file, [&](std::ostream& out) {
    out.write(kCacheMagic, 8);
    const std::uint64_t len = header.size();
    out.write(reinterpret_cast<const char*>(&len), sizeof len);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    for (const at::Tensor* t : cache_tensors(d))
      out.write(static_cast<const char*>(t->data_ptr()), static_cast<std::streamsize>(t->nbytes()));
  });
}

// The cached features, or nothing (with the reason at debug level) when the file is
// missing, unreadable or out of date.
std::optional<DatasetSequence> read_cache(const std::string& file, const std::string& source, const Inputs& in) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return std::nullopt;
  auto stale = [&](const std::string& why) {
    log::debug("feature cache {}: {}; recomputing", file, why);
    return std::nullopt;
  };
  std::ifstream f(file, std::ios::binary);
  char magic[8];
  std::uint64_t len = 0;
  if (!f.read(magic, 8) || std::memcmp(magic, kCacheMagic, 8) != 0) return stale("not a feature cache file");
  if (!f.read(reinterpret_cast<char*>(&len), sizeof len) || len > (1u << 20)) return stale("bad header");
  std::string text(len, '\0');
  if (!f.read(text.data(), static_cast<std::streamsize>(len))) return stale("truncated header");
  json h;
  try {
    h = json::parse(text);
    const SourceStamp src = stamp_of(source);
    if (h.at("cache_version").get<int>() != kCacheVersion) return stale("other cache version");
    if (h.at("variant").get<std::string>() != bps_variant_name(in.variant)) return stale("other variant");
    if (h.at("storage").get<std::string>() != (in.half ? "f2" : "f4")) return stale("other storage type");
    if (h.at("basis").get<std::string>() != in.basis_fingerprint) return stale("other basis");
    if (h.at("hands").get<std::string>() != hand_info().fingerprint) return stale("other hand model");
    // Files written before the MANO representation existed have no "mano" entry: valid
    // without it, stale for a data set that needs it.
    const bool has_mano = h.value("mano", false);
    if (in.mano && !has_mano) return stale("no MANO representation");
    if (h.at("source_size").get<std::uint64_t>() != src.size || h.at("source_mtime").get<std::int64_t>() != src.mtime)
      return stale("the sequence file changed");
    DatasetSequence d;
    d.path = source;
    d.name = h.at("name").get<std::string>();
    d.category = h.at("category").get<std::string>();
    d.kind = h.at("kind").get<std::string>();
    d.object_path = h.at("object").get<std::string>();
    if (h.at("object_mtime").get<std::int64_t>() != object_stamp(d.object_path)) return stale("the object changed");
    d.fps = h.at("fps").get<double>();
    d.scale = h.at("scale").get<double>();
    d.frames = h.at("frames").get<std::int64_t>();
    const int64_t n = d.frames, u = h.at("rows").get<std::int64_t>(), dyn = h.at("dynamic_rows").get<std::int64_t>();
    if (n < 1 || u < 1 || u > n || dyn < 0 || dyn > kBasisRows) return stale("bad sizes");
    const at::ScalarType store = in.half ? at::kHalf : at::kFloat;
    const at::ScalarType hit_type = h.at("hit_dtype").get<std::string>() == "i2" ? at::kShort : at::kInt;
    d.states = at::empty({n, 7}, at::kFloat);
    d.feature_row = at::empty({n}, at::kInt);
    d.object_template = at::empty({kBasisRows, 3}, store);
    d.hit_template = at::empty({kBasisRows}, hit_type);
    d.dynamic_rows = at::empty({dyn}, at::kInt);
    d.object_features = at::empty({u, dyn, 3}, store);
    d.hit_indices = at::empty({u, dyn}, hit_type);
    d.contact_maps = at::empty({n, 2, kBasisRows}, store);
    d.hand_features = at::empty({n, kHandFeatureSize}, store);
    if (has_mano) d.mano = at::empty({n, kManoRepSize}, store);
    for (const at::Tensor* t : cache_tensors(d))
      if (!f.read(static_cast<char*>(t->data_ptr()), static_cast<std::streamsize>(t->nbytes())))
        return stale("truncated data");
    if (f.peek() != std::char_traits<char>::eof()) return stale("trailing data");
    const int32_t* rows = d.feature_row.data_ptr<int32_t>();
    for (int64_t t = 0; t < n; ++t)
      if (rows[t] < 0 || rows[t] >= u) return stale("bad feature rows");
    const int32_t* dr = d.dynamic_rows.data_ptr<int32_t>();
    for (int64_t k = 0; k < dyn; ++k)
      if (dr[k] < 0 || dr[k] >= kBasisRows || (k > 0 && dr[k] <= dr[k - 1])) return stale("bad dynamic rows");
    if (!in.mano) d.mano = at::Tensor();  // read past, not kept
    return d;
  } catch (const std::exception& e) {
    return stale(std::string("unreadable header: ") + e.what());
  }
}

std::string cache_file_for(const std::string& cache_dir, const std::string& cache_base, const std::string& file) {
  if (!cache_base.empty()) {
    const fs::path rel = fs::path(file).lexically_normal().lexically_relative(fs::path(cache_base).lexically_normal());
    if (!rel.empty() && *rel.begin() != "..") return (fs::path(cache_dir) / rel).string() + ".features";
  }
  Fnv f;
  f.add(fs::absolute(file).lexically_normal().string());
  return (fs::path(cache_dir) / (fs::path(file).stem().string() + "_" + f.hex() + ".features")).string();
}

// An unbiased index in [0, n) from the generator's raw 64-bit output.
std::uint64_t uniform_index(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t x;
  do x = rng();
  while (x >= limit);
  return x % n;
}

std::string human_bytes(double b) {
  const char* units[] = {"B", "KB", "MB", "GB"};
  int u = 0;
  while (b >= 1024 && u < 3) b /= 1024, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f %s", b, units[u]);
  return buf;
}

}  // namespace

std::string bps_variant_name(BpsVariant variant) {
  switch (variant) {
    case BpsVariant::Uniform: return "u_bps";
    case BpsVariant::PartAgnostic: return "npa_bps";
    case BpsVariant::PerPart: return "np_bps";
  }
  return "";
}

BpsVariant parse_bps_variant(const std::string& name) {
  for (BpsVariant v : {BpsVariant::PerPart, BpsVariant::PartAgnostic, BpsVariant::Uniform})
    if (bps_variant_name(v) == name) return v;
  const std::vector<std::string> known{"np_bps", "npa_bps", "u_bps"};
  throw Error("unknown encoder variant '" + name + "'" + did_you_mean(name, known) + " (known: " + join(known, ", ") +
              ")");
}

std::vector<std::int64_t> WindowDataset::spread(std::int64_t count) const {
  const auto size = static_cast<std::int64_t>(this->size());
  const std::int64_t n = std::min(std::max<std::int64_t>(count, 0), size);
  std::vector<std::int64_t> idx;
  for (std::int64_t i = 0; i < n; ++i) idx.push_back(i * size / n);
  return idx;
}

std::vector<std::int32_t> window_starts(std::int64_t frames, int window, int stride) {
  if (window < 1 || stride < 1) throw Error("windows need window >= 1 and stride >= 1");
  std::vector<std::int32_t> out;
  if (frames <= window) return {0};
  for (std::int64_t s = 0; s + window <= frames; s += stride) out.push_back(static_cast<std::int32_t>(s));
  if (out.back() + window < frames) out.push_back(static_cast<std::int32_t>(frames - window));
  return out;
}

std::size_t DatasetSequence::bytes() const {
  std::size_t b = 0;
  for (const at::Tensor* t : cache_tensors(*this))
    if (t->defined()) b += t->nbytes();
  return b;
}

at::Tensor DatasetSequence::object_rows() const {
  const int64_t u = object_features.size(0);
  at::Tensor out = object_template.to(at::kFloat).unsqueeze(0).repeat({u, 1, 1});
  out.index_copy_(1, dynamic_rows.to(at::kLong), object_features.to(at::kFloat));
  return out;
}

at::Tensor DatasetSequence::hit_rows() const {
  const int64_t u = hit_indices.size(0);
  at::Tensor out = hit_template.to(at::kLong).unsqueeze(0).repeat({u, 1});
  out.index_copy_(1, dynamic_rows.to(at::kLong), hit_indices.to(at::kLong));
  return out;
}

WindowDataset WindowDataset::open(const std::string& folder, const std::string& split,
                                  const WindowDatasetOptions& options) {
  const DatasetManifest m = read_manifest(folder);
  const std::vector<std::string> files = split_files(m, folder, split);
  if (files.empty())
    throw Error((fs::path(folder) / "manifest.json").string() + ": the \"" + split + "\" split lists no sequences");
  std::string cache_dir;
  if (options.cache)
    cache_dir = options.cache_dir.empty() ? (fs::path(folder) / "cache" / bps_variant_name(options.variant)).string()
                                          : options.cache_dir;
  WindowDataset ds = load(files, folder, cache_dir, options);
  for (const DatasetSequence& s : ds.sequences_)
    if (std::abs(s.fps - m.fps) > 1e-6 * m.fps) {
      log::warn("{}: {} fps, but the data set's manifest says {} fps; windows count frames, not seconds", s.path, s.fps,
                m.fps);
      break;
    }
  return ds;
}

WindowDataset WindowDataset::from_files(const std::vector<std::string>& files, const WindowDatasetOptions& options) {
  if (files.empty()) throw Error("a window data set needs at least one sequence file");
  return load(files, "", options.cache ? options.cache_dir : "", options);
}

WindowDataset WindowDataset::load(const std::vector<std::string>& files, const std::string& cache_base,
                                  const std::string& cache_dir, const WindowDatasetOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (options.window < 1)
    throw Error("window data set: window must be >= 1 frame, got " + std::to_string(options.window));
  if (options.stride < 1)
    throw Error("window data set: stride must be >= 1 frame, got " + std::to_string(options.stride));
  WindowDataset ds;
  ds.window_ = options.window;
  ds.stride_ = options.stride;
  ds.variant_ = options.variant;
  ds.basis_file_ =
      options.basis_file.empty() ? find_data_file(default_basis_file(options.variant)) : options.basis_file;
  ds.basis_ = load_bps_basis(ds.basis_file_);
  if (ds.basis_.points.rows() != basis_size(options.variant))
    throw Error(ds.basis_file_ + ": the basis has " + std::to_string(ds.basis_.points.rows()) + " points; " +
                bps_variant_name(options.variant) + " needs " + std::to_string(basis_size(options.variant)));
  hand_info();  // load the hand models once, before the workers start
  const Inputs in{options.variant, &ds.basis_, basis_fingerprint(ds.basis_), options.half_precision, options.mano};

  const std::size_t n = files.size();
  ds.sequences_.resize(n);
  std::vector<std::string> errors(n);
  std::vector<char> from_cache(n, 0);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false}, warned{false};
  std::mutex progress_mutex;
  std::size_t done = 0;
  ObjectStore objects;

  auto work = [&] {
    for (std::size_t i; !failed && (i = next++) < n;) {
      const std::string& file = files[i];
      try {
        const std::string cache_file = cache_dir.empty() ? "" : cache_file_for(cache_dir, cache_base, file);
        std::optional<DatasetSequence> cached;
        if (!cache_file.empty()) cached = read_cache(cache_file, file, in);
        if (cached) {
          ds.sequences_[i] = std::move(*cached);
          from_cache[i] = 1;
        } else {
          const SourceStamp src = stamp_of(file);  // before reading: a later change invalidates
          ds.sequences_[i] = compute_sequence(file, objects, in);
          if (!cache_file.empty()) {
            try {
              write_cache(cache_file, ds.sequences_[i], in, src);
            } catch (const std::exception& e) {
              if (!warned.exchange(true)) log::warn("feature cache not written ({}); continuing without it", e.what());
            }
          }
        }
      } catch (const std::exception& e) {
        const std::string what = e.what();
        errors[i] = what.find(file) == std::string::npos ? file + ": " + what : what;
        failed = true;
      }
      std::lock_guard<std::mutex> lock(progress_mutex);
      ++done;
      if (options.progress) options.progress(done, n);
    }
  };
  const int64_t workers =
      std::min<int64_t>(options.threads > 0 ? options.threads : at::get_num_threads(), static_cast<int64_t>(n));
  if (workers <= 1) {
    work();
  } else {
    // Plain threads, one sequence each at a time, each with one libtorch/OpenMP thread:
    // nesting the work in an OpenMP region instead made it ~2.7x slower on a loaded 2-core
    // box (spin-waiting; docs/data_loader.md). A new thread takes its OpenMP thread count
    // from the process-wide setting, which is restored afterwards.
    const int caller_threads = at::get_num_threads();
    std::vector<std::thread> pool;
    for (int64_t t = 0; t < workers; ++t)
      pool.emplace_back([&] {
        at::set_num_threads(1);
        work();
      });
    for (auto& t : pool) t.join();
    at::set_num_threads(caller_threads);
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!errors[i].empty()) throw Error(errors[i]);

  bool mixed_fps = false;
  for (std::size_t i = 0; i < n; ++i) {
    const DatasetSequence& s = ds.sequences_[i];
    for (std::int32_t start : window_starts(s.frames, ds.window_, ds.stride_))
      ds.windows_.push_back({static_cast<std::int32_t>(i), start});
    if (s.fps != ds.sequences_[0].fps && !mixed_fps && (mixed_fps = true))
      log::warn("{}: {} fps, but {} has {} fps; windows count frames, not seconds", s.path, s.fps,
                ds.sequences_[0].path, ds.sequences_[0].fps);
  }
  ds.report_.cached = static_cast<std::size_t>(std::count(from_cache.begin(), from_cache.end(), 1));
  ds.report_.computed = n - ds.report_.cached;
  ds.report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  log::info("data: {} sequences ({} computed, {} cached) in {:.1f} s: {} frames, {} windows of {}, features {}", n,
            ds.report_.computed, ds.report_.cached, ds.report_.seconds, ds.num_frames(), ds.windows_.size(), ds.window_,
            human_bytes(static_cast<double>(ds.memory_bytes())));
  return ds;
}

std::int64_t WindowDataset::num_frames() const {
  std::int64_t n = 0;
  for (const DatasetSequence& s : sequences_) n += s.frames;
  return n;
}

std::size_t WindowDataset::memory_bytes() const {
  std::size_t b = windows_.size() * sizeof(WindowRef);
  for (const DatasetSequence& s : sequences_) b += s.bytes();
  return b;
}

at::Tensor WindowDataset::basis_points() const {
  const int k = static_cast<int>(basis_.points.rows());
  at::Tensor out = at::empty({kBasisRows, 3}, at::kFloat);
  auto B = out.accessor<float, 2>();
  for (int row = 0; row < kBasisRows; ++row)
    for (int c = 0; c < 3; ++c) B[row][c] = static_cast<float>(basis_.points(row % k, c));
  return out;
}

WindowBatch WindowDataset::batch(const std::vector<std::int64_t>& indices) const {
  const int64_t b_count = static_cast<int64_t>(indices.size()), w = window_;
  if (b_count == 0) throw Error("window batch: no window indices given");
  for (int64_t idx : indices)
    if (idx < 0 || idx >= static_cast<int64_t>(windows_.size()))
      throw Error("window batch: index " + std::to_string(idx) + " is out of range (the data set has " +
                  std::to_string(windows_.size()) + " windows)");
  const at::ScalarType store = sequences_.front().object_template.scalar_type();
  const std::size_t es = c10::elementSize(store);
  at::Tensor O = at::empty({b_count, w, kBasisRows, 3}, store);
  at::Tensor C = at::empty({b_count, w, 2, kBasisRows}, store);
  at::Tensor X = at::empty({b_count, w, kHandFeatureSize}, store);
  const bool mano = sequences_.front().mano.defined();
  at::Tensor M = mano ? at::empty({b_count, w, kManoRepSize}, store) : at::Tensor();
  WindowBatch out;
  out.hit_indices = at::empty({b_count, w, kBasisRows}, at::kLong);
  out.global_states = at::empty({b_count, w, 7}, at::kFloat);
  out.object_states = at::empty({b_count, w, 7}, at::kFloat);
  out.mask = at::empty({b_count, w}, at::kFloat);
  out.sequence = at::empty({b_count}, at::kLong);
  out.start = at::empty({b_count}, at::kLong);
  char* o_out = static_cast<char*>(O.data_ptr());
  char* c_out = static_cast<char*>(C.data_ptr());
  char* x_out = static_cast<char*>(X.data_ptr());
  char* m_rep_out = mano ? static_cast<char*>(M.data_ptr()) : nullptr;
  int64_t* h_out = out.hit_indices.data_ptr<int64_t>();
  float* g_out = out.global_states.data_ptr<float>();
  float* s_out = out.object_states.data_ptr<float>();
  float* m_out = out.mask.data_ptr<float>();
  int64_t* seq_out = out.sequence.data_ptr<int64_t>();
  int64_t* start_out = out.start.data_ptr<int64_t>();

  at::parallel_for(0, b_count, 8, [&](int64_t b0, int64_t b1) {
    for (int64_t b = b0; b < b1; ++b) {
      const WindowRef ref = windows_[static_cast<std::size_t>(indices[static_cast<std::size_t>(b)])];
      const DatasetSequence& s = sequences_[static_cast<std::size_t>(ref.sequence)];
      seq_out[b] = ref.sequence;
      start_out[b] = ref.start;
      const float* S = s.states.data_ptr<float>();
      const int32_t* rows = s.feature_row.data_ptr<int32_t>();
      const char* o_tmpl = static_cast<const char*>(s.object_template.data_ptr());
      const char* o_in = static_cast<const char*>(s.object_features.data_ptr());
      const char* c_in = static_cast<const char*>(s.contact_maps.data_ptr());
      const char* x_in = static_cast<const char*>(s.hand_features.data_ptr());
      const int32_t* dyn = s.dynamic_rows.data_ptr<int32_t>();
      const int64_t d_count = s.dynamic_rows.size(0);
      const bool short_hits = s.hit_template.scalar_type() == at::kShort;
      const float* first = S + 7 * ref.start;
      for (int64_t i = 0; i < w; ++i) {
        const int64_t bi = b * w + i;
        const int64_t f = std::min<int64_t>(ref.start + i, s.frames - 1);
        const int64_t r = rows[f];
        char* o = o_out + bi * kObjectRow * es;
        std::memcpy(o, o_tmpl, kObjectRow * es);
        for (int64_t k = 0, run; k < d_count; k += run) {  // runs of consecutive rows at once
          for (run = 1; k + run < d_count && dyn[k + run] == dyn[k] + run;) ++run;
          std::memcpy(o + dyn[k] * 3 * es, o_in + (r * d_count + k) * 3 * es, run * 3 * es);
        }
        std::memcpy(c_out + bi * kContactRow * es, c_in + f * kContactRow * es, kContactRow * es);
        std::memcpy(x_out + bi * kHandFeatureSize * es, x_in + f * kHandFeatureSize * es, kHandFeatureSize * es);
        if (mano)
          std::memcpy(m_rep_out + bi * kManoRepSize * es, static_cast<const char*>(s.mano.data_ptr()) + f * kManoRepSize * es,
                      kManoRepSize * es);
        int64_t* h = h_out + bi * kBasisRows;
        if (short_hits) {
          const int16_t* tmpl = s.hit_template.data_ptr<int16_t>();
          const int16_t* hi = s.hit_indices.data_ptr<int16_t>() + r * d_count;
          for (int k = 0; k < kBasisRows; ++k) h[k] = tmpl[k];
          for (int64_t k = 0; k < d_count; ++k) h[dyn[k]] = hi[k];
        } else {
          const int32_t* tmpl = s.hit_template.data_ptr<int32_t>();
          const int32_t* hi = s.hit_indices.data_ptr<int32_t>() + r * d_count;
          for (int k = 0; k < kBasisRows; ++k) h[k] = tmpl[k];
          for (int64_t k = 0; k < d_count; ++k) h[dyn[k]] = hi[k];
        }
        const float* st = S + 7 * f;
        float* g = g_out + bi * 7;
        std::memcpy(s_out + bi * 7, st, 7 * sizeof(float));
        for (int c = 0; c < 3; ++c) {
          g[c] = st[1 + c];
          g[3 + c] = static_cast<float>(static_cast<double>(st[4 + c]) - static_cast<double>(first[4 + c]));
        }
        g[6] = static_cast<float>(s.scale);
        m_out[bi] = ref.start + i < s.frames ? 1.0f : 0.0f;
      }
    }
  });
  out.object_features = O.to(at::kFloat);
  out.contact_maps = C.to(at::kFloat);
  out.hand_features = X.to(at::kFloat);
  if (mano) out.mano = M.to(at::kFloat);
  return out;
}

WindowBatch WindowDataset::sample_batch(std::int64_t batch_size, std::mt19937_64& rng) const {
  if (batch_size < 1) throw Error("window batch: the batch size must be >= 1, got " + std::to_string(batch_size));
  const std::uint64_t n = windows_.size();
  std::vector<std::int64_t> picked(static_cast<std::size_t>(batch_size));
  if (static_cast<std::uint64_t>(batch_size) <= n) {
    std::vector<std::int64_t> all(n);
    for (std::uint64_t i = 0; i < n; ++i) all[i] = static_cast<std::int64_t>(i);
    for (std::int64_t i = 0; i < batch_size; ++i) {  // partial Fisher-Yates
      const std::uint64_t j = static_cast<std::uint64_t>(i) + uniform_index(rng, n - static_cast<std::uint64_t>(i));
      std::swap(all[static_cast<std::size_t>(i)], all[j]);
      picked[static_cast<std::size_t>(i)] = all[static_cast<std::size_t>(i)];
    }
  } else {
    for (auto& p : picked) p = static_cast<std::int64_t>(uniform_index(rng, n));
  }
  return batch(picked);
}

std::vector<std::int64_t> WindowDataset::shuffled(std::mt19937_64& rng) const {
  const std::uint64_t n = windows_.size();
  std::vector<std::int64_t> all(n);
  for (std::uint64_t i = 0; i < n; ++i) all[i] = static_cast<std::int64_t>(i);
  for (std::uint64_t i = n; i > 1; --i) std::swap(all[i - 1], all[uniform_index(rng, i)]);
  return all;
}

}  // namespace bimart
