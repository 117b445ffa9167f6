#include "core/object/object_import.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "core/geometry/rotation.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"
#include "core/object/part_checks.h"
#include "core/util/atomic_folder.h"
#include "core/util/error.h"
#include "core/util/output_path.h"

namespace bimart {

namespace fs = std::filesystem;

namespace {

// Area-weighted centroid of the surface (independent of how finely it is meshed).
Eigen::Vector3d surface_centroid(const TriangleMesh& m) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    const double w = 0.5 * (b - a).cross(c - a).norm();
    sum += w * (a + b + c) / 3;
    area += w;
  }
  return area > 0 ? Eigen::Vector3d(sum / area) : Eigen::Vector3d(m.vertices.colwise().mean());
}

void transform(TriangleMesh& m, const Eigen::Isometry3d& t) {
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    m.vertices.row(i) = (t * Eigen::Vector3d(m.vertices.row(i))).transpose();
}

// Reads and checks one part, in metres.
TriangleMesh read_part(const std::string& path, double scale, ImportedPart& info) {
  info.file = path;
  TriangleMesh m = read_mesh_file(path);
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
  TriangleMesh top = read_part(opt.top, scale, rep.top);
  TriangleMesh bottom = read_part(opt.bottom, scale, rep.bottom);
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
  rep.top.repair = close_and_orient(top, opt.top);
  rep.bottom.repair = close_and_orient(bottom, opt.bottom);

  // 2. About the axis: the top part above the bottom part (+y), as in every family.
  const Eigen::Vector3d ct = surface_centroid(top), cb = surface_centroid(bottom);
  const Eigen::Vector2d up = (ct - cb).head<2>();
  Eigen::Isometry3d roll = Eigen::Isometry3d::Identity();
  if (up.norm() > 1e-3 * extent) {
    roll.linear() = rotation_about(Eigen::Vector3d::UnitZ(), M_PI / 2 - std::atan2(up.y(), up.x()));
  } else {
    // Top and bottom side by side along the axis: put the whole object towards -x instead.
    const Eigen::Vector2d c = (0.5 * (ct + cb)).head<2>();
    if (c.norm() > 1e-3 * extent) roll.linear() = rotation_about(Eigen::Vector3d::UnitZ(), M_PI - std::atan2(c.y(), c.x()));
  }
  // 3. Along the axis: the extent along z centred on the origin.
  transform(top, roll);
  transform(bottom, roll);
  const double zlo = std::min(top.vertices.col(2).minCoeff(), bottom.vertices.col(2).minCoeff());
  const double zhi = std::max(top.vertices.col(2).maxCoeff(), bottom.vertices.col(2).maxCoeff());
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = Eigen::Vector3d(0, 0, -0.5 * (zlo + zhi));
  transform(top, shift);
  transform(bottom, shift);
  rep.to_canonical = shift * roll * t;

  for (const auto& [mesh, file] : {std::pair{&top, &opt.top}, {&bottom, &opt.bottom}}) {
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
  o.units_note = fmt::format("imported from {} and {} ({})", fs::path(opt.top).filename().string(),
                             fs::path(opt.bottom).filename().string(), opt.units);

  rep.size = object_size(o);
  if (rep.size < kTrainingSizeMin / kSizeWarningFactor || rep.size > kTrainingSizeMax * kSizeWarningFactor)
    rep.warnings.push_back(fmt::format(
        "the object is {:.3g} m across, far outside the {:.2g}-{:.2g} m of the objects the models were trained on: "
        "check --units; generated hands may not fit it",
        rep.size, kTrainingSizeMin, kTrainingSizeMax));
  const double cx = 0.5 * (surface_centroid(o.top).x() + surface_centroid(o.bottom).x());
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
