#include "core/object/object_import.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/geometry/rotation.h"
#include "core/object/canonical_frame.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"
#include "core/object/part_checks.h"
#include "core/util/atomic_folder.h"
#include "core/util/error.h"
#include "core/util/output_path.h"
#include "core/util/text.h"

namespace bimart {

namespace fs = std::filesystem;

namespace {

void transform(TriangleMesh& m, const Eigen::Isometry3d& t) {
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    m.vertices.row(i) = (t * Eigen::Vector3d(m.vertices.row(i))).transpose();
}

// The faces of `m` where `keep[f]`, with only the vertices they use.
TriangleMesh select_faces(const TriangleMesh& m, const std::vector<bool>& keep) {
  std::vector<int> index(m.num_vertices(), -1);
  std::vector<Eigen::Index> vertices, faces;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f)
    if (keep[f]) {
      faces.push_back(f);
      for (int c = 0; c < 3; ++c)
        if (index[m.faces(f, c)] < 0) {
          index[m.faces(f, c)] = static_cast<int>(vertices.size());
          vertices.push_back(m.faces(f, c));
        }
    }
  TriangleMesh out;
  out.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t i = 0; i < vertices.size(); ++i) out.vertices.row(i) = m.vertices.row(vertices[i]);
  out.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int c = 0; c < 3; ++c) out.faces(i, c) = index[m.faces(faces[i], c)];
  return out;
}

// Reads and checks one part, in metres (`given`: already read, e.g. split from one file).
TriangleMesh read_part(const std::string& path, double scale, ImportedPart& info, const TriangleMesh* given = nullptr) {
  info.file = path;
  TriangleMesh m = given ? *given : read_mesh_file(path);
  validate_mesh(m, path);
  info.vertices_read = m.num_vertices();
  info.faces_read = m.num_faces();
  info.closed_as_read = is_closed_mesh(m);
  m.vertices *= scale;
  const double r = bounding_radius(m);
  if (r < kMinPartRadius || r > kMaxPartRadius)
    throw Error(fmt::format("{}: the part's bounding radius is {:.4g} m in {}, outside [{}, {}] m (wrong --units?)",
                            path, r, scale == 1 ? "m" : scale == 0.01 ? "cm" : "mm", kMinPartRadius, kMaxPartRadius));
  return m;
}

double deg(double rad) { return rad * 180 / M_PI; }

}  // namespace

std::pair<TriangleMesh, TriangleMesh> split_labelled_obj(const std::string& path, const std::string& top_label) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".obj") throw Error(path + ": part labels are read from OBJ groups (g or o lines); give two files instead");
  const TriangleMesh m = read_mesh_file(path);  // checked; polygons split as fans, in file order
  // The group of every face line, one entry per triangle it becomes.
  std::ifstream in(path);
  std::vector<bool> top;
  std::vector<std::string> groups;
  std::string line, group = "(no group)";
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string kind;
    ls >> kind;
    if (kind == "g" || kind == "o") {
      std::string name, word;
      while (ls >> word) name += (name.empty() ? "" : " ") + word;
      group = name.empty() ? "(no group)" : name;
      if (std::find(groups.begin(), groups.end(), group) == groups.end()) groups.push_back(group);
    } else if (kind == "f") {
      int corners = 0;
      std::string word;
      while (ls >> word) ++corners;
      for (int k = 0; k + 2 < corners; ++k) top.push_back(group == top_label);
    }
  }
  if (static_cast<Eigen::Index>(top.size()) != m.num_faces())
    throw Error(fmt::format("{}: counted {} triangles in its face lines but read {}", path, top.size(), m.num_faces()));
  const auto n_top = std::count(top.begin(), top.end(), true);
  const std::string names = groups.empty() ? "none" : "'" + join(groups, "', '") + "'";
  if (n_top == 0)
    throw Error(fmt::format("{}: no group '{}' with faces (its groups: {})", path, top_label, names));
  if (n_top == m.num_faces())
    throw Error(fmt::format("{}: every face is in group '{}'; the fixed part needs the others (its groups: {})", path,
                            top_label, names));
  std::vector<bool> bottom(top.size());
  for (std::size_t f = 0; f < top.size(); ++f) bottom[f] = !top[f];
  return {select_faces(m, top), select_faces(m, bottom)};
}

HingeAxis hinge_through(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return {a, b - a}; }

double object_size(const ArticulatedObject& o) {
  Eigen::Vector3d lo = o.top.vertices.colwise().minCoeff(), hi = o.top.vertices.colwise().maxCoeff();
  lo = lo.cwiseMin(Eigen::Vector3d(o.bottom.vertices.colwise().minCoeff()));
  hi = hi.cwiseMax(Eigen::Vector3d(o.bottom.vertices.colwise().maxCoeff()));
  return (hi - lo).maxCoeff();
}

std::pair<double, double> procedural_size_range(int seeds) {
  double lo = INFINITY, hi = 0;
  for (const std::string& category : object_categories())
    for (int s = 0; s < seeds; ++s) {
      const double size = object_size(make_object(category, static_cast<std::uint64_t>(s)));
      lo = std::min(lo, size);
      hi = std::max(hi, size);
    }
  return {lo, hi};
}

ArticulatedObject import_object(const ImportOptions& opt, ImportReport* out) {
  ImportReport rep;
  double scale = 1;
  try {
    scale = metres_per_unit(opt.units);
  } catch (const Error& e) {
    throw Error("--units: " + e.message());
  }
  if (!opt.hinge.point.allFinite() || !opt.hinge.direction.allFinite())
    throw Error("the hinge point and direction must be finite numbers");
  ArticulatedObject o;
  o.name = opt.name;
  o.category = opt.category;
  TriangleMesh top, bottom;
  if (!opt.labelled.empty()) {
    const auto parts = split_labelled_obj(opt.labelled, opt.top_label);
    top = read_part(opt.labelled + " (group " + opt.top_label + ")", scale, rep.top, &parts.first);
    bottom = read_part(opt.labelled + " (other groups)", scale, rep.bottom, &parts.second);
  } else {
    top = read_part(opt.top, scale, rep.top);
    bottom = read_part(opt.bottom, scale, rep.bottom);
  }
  const std::string top_name = rep.top.file, bottom_name = rep.bottom.file;
  const double extent = std::max(bounding_radius(top), bounding_radius(bottom));
  // Zero against the parts' size: the direction is in the files' units like the points.
  if (!(opt.hinge.direction.norm() * scale > 1e-9 * extent))
    throw Error(fmt::format("the hinge direction is zero ({}, {}, {}): give a direction, or two different points on "
                            "the axis",
                            opt.hinge.direction.x(), opt.hinge.direction.y(), opt.hinge.direction.z()));

  // 1. The axis to -z through the origin.
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rotation_between(opt.hinge.direction, Eigen::Vector3d(0, 0, -1));
  t.translation() = -(t.linear() * (scale * opt.hinge.point));
  transform(top, t);
  transform(bottom, t);
  rep.top.repair = close_and_orient(top, top_name);
  rep.bottom.repair = close_and_orient(bottom, bottom_name);

  // 2. About the axis: the top part above the bottom part (+y), as in every family; 3. along
  // it, the extent centred on the origin (core/object/canonical_frame.h).
  const Eigen::Isometry3d about = canonical_pose_about_hinge(top, bottom, extent);
  transform(top, about);
  transform(bottom, about);
  rep.to_canonical = about * t;

  for (const auto& [mesh, file] : {std::pair{&top, &top_name}, {&bottom, &bottom_name}}) {
    try {
      check_part_shape(*mesh, *file);
    } catch (const Error& e) {
      throw Error(e.message() + fmt::format(" (hinge point ({}, {}, {}) {})", opt.hinge.point.x(), opt.hinge.point.y(),
                                            opt.hinge.point.z(), opt.units));
    }
  }
  o.top = std::move(top);
  o.bottom = std::move(bottom);

  // Limits: given, else the category's, else [0, 180] deg.
  o.angle_min = 0;
  o.angle_max = M_PI;
  o.open_angle = M_PI / 2;
  if (!opt.category.empty()) {
    const ObjectFamily& f = object_family(opt.category);
    o.angle_min = f.angle_min;
    o.angle_max = f.angle_max;
    o.open_angle = f.open_angle;
  }
  if (opt.limits) {
    std::tie(o.angle_min, o.angle_max) = *opt.limits;
    if (!(std::isfinite(o.angle_min) && std::isfinite(o.angle_max) && o.angle_min < o.angle_max))
      throw Error(fmt::format("--limits must be finite with min < max, got [{}, {}] deg", deg(o.angle_min),
                              deg(o.angle_max)));
    if (!opt.open_angle) o.open_angle = 0.5 * (o.angle_min + o.angle_max);
  }
  if (opt.open_angle) o.open_angle = *opt.open_angle;
  if (!(std::isfinite(o.open_angle) && o.open_angle >= o.angle_min && o.open_angle <= o.angle_max))
    throw Error(fmt::format("--open {} deg is outside the limits [{}, {}] deg", deg(o.open_angle), deg(o.angle_min),
                            deg(o.angle_max)));
  o.units_note = opt.labelled.empty() ? fmt::format("imported from {} and {} ({})", fs::path(opt.top).filename().string(),
                                                    fs::path(opt.bottom).filename().string(), opt.units)
                                      : fmt::format("imported from {} ({})", fs::path(opt.labelled).filename().string(),
                                                    opt.units);

  rep.size = object_size(o);
  if (rep.size < kTrainingSizeMin / kSizeWarningFactor || rep.size > kTrainingSizeMax * kSizeWarningFactor)
    rep.warnings.push_back(fmt::format(
        "the object is {:.3g} m across, far outside the {:.2g}-{:.2g} m of the objects the models were trained on: "
        "check --units; generated hands may not fit it",
        rep.size, kTrainingSizeMin, kTrainingSizeMax));
  const double cx = 0.5 * (surface_centroid(o.top).x() + surface_centroid(o.bottom).x());
  const Eigen::Vector2d up = (surface_centroid(o.top) - surface_centroid(o.bottom)).head<2>();
  if (up.norm() > 1e-3 * extent && cx > 0)
    rep.warnings.push_back(
        "with this hinge direction a positive angle turns the top part into the bottom part (the object lies on "
        "the +x side of the hinge once the top is above the bottom): is the direction reversed?");
  if (out) *out = std::move(rep);
  return o;
}

std::string ImportReport::str() const {
  std::string s;
  for (const auto& [label, p] : {std::pair{"top", &top}, {"bottom", &bottom}})
    s += fmt::format("{:<7} {}: {} vertices, {} faces, {}\n", label, p->file, p->vertices_read, p->faces_read,
                     !p->repair.changed() ? std::string(p->closed_as_read ? "closed" : "closed after orienting")
                                          : std::string(p->closed_as_read ? "closed; " : "open; ") + p->repair.str());
  s += fmt::format("size    {:.4g} m (largest side; training objects {:.2g}-{:.2g} m)\n", size, kTrainingSizeMin,
                   kTrainingSizeMax);
  return s;
}

void check_object_output(const std::string& dir, bool force) {
  if (dir.empty()) throw Error("--out: give a folder");
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw Error("cannot write " + dir + ": it is a file, not a folder");
    const bool empty = fs::is_empty(dir, ec);
    if (!empty && !fs::exists(fs::path(dir) / "object.yaml", ec))
      throw Error("cannot write " + dir + ": the folder holds other files and no object.yaml; choose a new folder");
    if (!empty && !force) throw Error("cannot write " + dir + ": it holds an object already (--force replaces it)");
  }
  fs::path clean = fs::absolute(dir).lexically_normal();
  if (clean.filename().empty()) clean = clean.parent_path();  // "out/" -> "out"
  check_output_folder(clean.parent_path().string());
}

void write_object_folder(const ArticulatedObject& object, const std::string& dir, bool force) {
  check_object_output(dir, force);
  write_folder_atomically(dir, [&](const std::string& tmp) { save_object(object, tmp); }, true);
}

}  // namespace bimart
