#include "core/trajectory/trajectory_object.h"

#include <cstdlib>
#include <filesystem>

#include "core/object/canonical_frame.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"
#include "core/util/fingerprint.h"
#include "core/util/output_path.h"

namespace bimart {

namespace fs = std::filesystem;

namespace {

fs::path cache_objects_dir() {
  fs::path base;
  if (const char* d = std::getenv("BIMART_CACHE_DIR"); d && *d) {
    base = d;
  } else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) {
    base = fs::path(x) / "bimart";
  } else if (const char* h = std::getenv("HOME"); h && *h) {
    base = fs::path(h) / ".cache" / "bimart";
  } else {
    base = fs::temp_directory_path() / "bimart-cache";
  }
  return base / "objects";
}

}  // namespace

std::string default_object_dir(const std::string& category, std::int64_t seed) {
  return (cache_objects_dir() / (category + "_" + std::to_string(seed))).string();
}

std::string canonical_object_dir(const ArticulatedObject& canonical) {
  Fnv f;
  for (const TriangleMesh* m : {&canonical.top, &canonical.bottom}) {
    const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> v = m->vertices;
    const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> t = m->faces.cast<int>();
    f.add(v.data(), static_cast<std::size_t>(v.size()) * sizeof(double));
    f.add(t.data(), static_cast<std::size_t>(t.size()) * sizeof(int));
  }
  f.add(canonical.name);
  std::string name = canonical.name.empty() ? std::string("object") : canonical.name;
  for (char& c : name)
    if (c == '/' || c == '\\' || c == ' ') c = '_';
  return (cache_objects_dir() / "canonical" / (name + "_" + f.hex())).string();
}

void make_canonical(TrajectoryObject& object) {
  CanonicalObject c = to_canonical(object.object);
  if (!c.moved) return;
  object.object = std::move(c.object);
  object.from_source = c.from_source;
  object.moved = true;
  if (!object.procedural) {
    object.path = canonical_object_dir(object.object);
    object.canonical_copy = true;
  }
}

TrajectoryObject resolve_trajectory_object(const ObjectReference& chosen, const ObjectReference& from_file,
                                           const std::string& trajectory_file, const std::string& object_dir) {
  const ObjectReference& ref = chosen.empty() ? from_file : chosen;
  if (ref.empty())
    throw Error(trajectory_file + ": the trajectory names no object; give the stage's `object` (a folder or "
                                  "object.yaml) or `category` and `seed`, or an `object:` in the file");
  if (!ref.path.empty() && !ref.category.empty())
    throw Error(ref.where, "give either an object path or a category, not both");
  TrajectoryObject out;
  try {
    if (!ref.path.empty()) {
      fs::path p(ref.path);
      if (p.is_relative()) p = fs::absolute(trajectory_file).parent_path() / p;
      out.path = p.lexically_normal().string();
      out.object = load_object(out.path);
      return out;
    }
    if (ref.seed < 0) throw Error("seed must be >= 0");
    out.object = make_object(ref.category, static_cast<std::uint64_t>(ref.seed));
  } catch (const Error& e) {
    if (e.where().known()) throw;
    throw Error(ref.where, e.message());
  }
  out.procedural = true;
  out.path = fs::absolute(object_dir.empty() ? default_object_dir(ref.category, ref.seed) : object_dir)
                 .lexically_normal()
                 .string();
  check_output_folder(out.path);  // fails now, not after the run
  return out;
}

void save_trajectory_object(const TrajectoryObject& object) {
  if (object.procedural || object.canonical_copy) save_object(object.object, object.path);
}

}  // namespace bimart
