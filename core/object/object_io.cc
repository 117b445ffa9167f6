#include "core/object/object_io.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>

#include "core/geometry/rotation.h"
#include "core/object/families/families.h"
#include "core/object/part_checks.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/text.h"
#include "core/util/yaml_keys.h"

namespace bimart {

namespace fs = std::filesystem;

namespace {

SourceLocation where(const std::string& file, const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return {file, m.line >= 0 ? m.line + 1 : 0, m.column >= 0 ? m.column + 1 : 0};
}

Eigen::Vector3d read_vec3(const std::string& file, const YAML::Node& n, const std::string& field) {
  if (!n.IsSequence() || n.size() != 3) throw Error(where(file, n), field + " must be a list of 3 numbers");
  Eigen::Vector3d v;
  try {
    for (int i = 0; i < 3; ++i) v[i] = n[i].as<double>();
  } catch (const YAML::Exception&) {
    throw Error(where(file, n), field + " must be a list of 3 numbers");
  }
  if (!v.allFinite()) throw Error(where(file, n), field + " holds a non-finite number");
  return v;
}

// Reads, checks, scales to metres, moves to the canonical frame, closes and orients a part.
TriangleMesh load_part(const std::string& path, double scale, const Eigen::Isometry3d& to_canonical,
                       RepairReport& report) {
  TriangleMesh m = read_mesh_file(path);
  validate_mesh(m, path);
  m.vertices *= scale;
  const double r = bounding_radius(m);
  if (r < kMinPartRadius || r > kMaxPartRadius)
    throw Error(fmt::format("{}: the part's bounding radius is {:.4g} m after units, outside [{}, {}] m "
                            "(wrong units?)",
                            path, r, kMinPartRadius, kMaxPartRadius));
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    m.vertices.row(i) = (to_canonical * Eigen::Vector3d(m.vertices.row(i))).transpose();
  report = close_and_orient(m, path);
  if (report.changed()) log::info("{}: {}", path, report.str());
  check_part_shape(m, path);
  return m;
}

void check_limits(ArticulatedObject& o, const std::string& file, const YAML::Node& node) {
  if (!(std::isfinite(o.angle_min) && std::isfinite(o.angle_max) && o.angle_min <= o.angle_max))
    throw Error(where(file, node), fmt::format("limits must be finite with min <= max, got [{}, {}]", o.angle_min,
                                               o.angle_max));
}

// Hinge limits of a known category, for files that do not give them.
void category_defaults(ArticulatedObject& o) {
  for (const auto& f : object_families())
    if (f.name == o.category) {
      o.angle_min = f.angle_min;
      o.angle_max = f.angle_max;
      o.open_angle = f.open_angle;
      return;
    }
  o.angle_min = 0;
  o.angle_max = M_PI;
  o.open_angle = M_PI / 2;
}

}  // namespace

void check_part_shape(const TriangleMesh& m, const std::string& path) {
  if (m.num_faces() < kMinPartFaces)
    throw Error(fmt::format("{}: the part has {} faces once closed; a solid part needs at least {} (is it a single "
                            "sheet or triangle?)",
                            path, m.num_faces(), kMinPartFaces));
  const double r = bounding_radius(m);
  const double volume = signed_volume(m);
  if (!(volume > kMinPartVolumeRatio * r * r * r))
    throw Error(fmt::format("{}: the part encloses {:.3g} m³ once closed, about zero for its size (radius {:.3g} "
                            "m): a flat or inside-out mesh is no solid part",
                            path, volume, r));
  const Eigen::Vector3d lo = m.vertices.colwise().minCoeff(), hi = m.vertices.colwise().maxCoeff();
  const double gap = lo.cwiseMax(-hi).cwiseMax(0.0).norm();  // box to the hinge point (origin)
  if (gap > kMaxHingeGapRatio * r + kMinPartRadius)
    throw Error(fmt::format("{}: the part is {:.3g} m from the hinge (its nearest point; its radius is {:.3g} m): "
                            "parts must touch the hinge; check hinge.pivot and units",
                            path, gap, r));
}

std::string ObjectLoadReport::str() const { return "top: " + top.str() + "; bottom: " + bottom.str(); }

double metres_per_unit(const std::string& units) {
  if (units == "m") return 1.0;
  if (units == "cm") return 0.01;
  if (units == "mm") return 0.001;
  throw Error("units must be m, cm or mm, got '" + units + "'");
}

ArticulatedObject load_object_yaml(const std::string& file, ObjectLoadReport* report) {
  YAML::Node root;
  std::string source;
  {
    std::ifstream in(file);
    if (!in) throw Error(file + ": cannot open the object file");
    std::stringstream ss;
    ss << in.rdbuf();
    source = ss.str();
  }
  try {
    root = YAML::Load(source);
  } catch (const YAML::ParserException& e) {
    throw Error(SourceLocation{file, e.mark.line + 1, e.mark.column + 1}, e.msg);
  }
  check_duplicate_keys(source, file);
  if (!root.IsMap()) throw Error(file + ": expected a map with name, top, bottom");
  static const std::vector<std::string> known = {"name", "category", "top", "bottom", "units", "hinge", "limits",
                                                 "open_angle"};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), key) == known.end())
      throw Error(where(file, kv.first), "unknown field '" + key + "'" + did_you_mean(key, known));
  }
  auto text = [&](const char* field, bool required) -> std::string {
    const YAML::Node n = root[field];
    if (!n) {
      if (required) throw Error(file + ": missing field '" + field + "'");
      return "";
    }
    if (!n.IsScalar()) throw Error(where(file, n), std::string(field) + " must be a string");
    return n.as<std::string>();
  };
  ArticulatedObject o;
  o.name = text("name", true);
  o.category = text("category", false);
  const std::string units = root["units"] ? text("units", false) : "m";
  double scale = 1;
  try {
    scale = metres_per_unit(units);
  } catch (const Error& e) {
    throw Error(where(file, root["units"]), e.message());
  }
  Eigen::Isometry3d to_canonical = Eigen::Isometry3d::Identity();
  if (const YAML::Node h = root["hinge"]) {
    if (!h.IsMap() || !h["pivot"] || !h["axis"])
      throw Error(where(file, h), "hinge must be a map with pivot: [x, y, z] and axis: [x, y, z]");
    const Eigen::Vector3d pivot = scale * read_vec3(file, h["pivot"], "hinge.pivot");
    const Eigen::Vector3d axis = read_vec3(file, h["axis"], "hinge.axis");
    if (axis.norm() < 1e-12) throw Error(where(file, h["axis"]), "hinge.axis must not be zero");
    to_canonical.linear() = rotation_between(axis, Eigen::Vector3d(0, 0, -1));
    to_canonical.translation() = -(to_canonical.linear() * pivot);
  }
  category_defaults(o);
  if (const YAML::Node l = root["limits"]) {
    if (!l.IsSequence() || l.size() != 2) throw Error(where(file, l), "limits must be [min, max] in radians");
    try {
      o.angle_min = l[0].as<double>();
      o.angle_max = l[1].as<double>();
    } catch (const YAML::Exception&) {
      throw Error(where(file, l), "limits must be [min, max] in radians");
    }
    check_limits(o, file, l);
    if (!root["open_angle"]) o.open_angle = 0.5 * (o.angle_min + o.angle_max);
  }
  if (const YAML::Node a = root["open_angle"]) {
    try {
      o.open_angle = a.as<double>();
    } catch (const YAML::Exception&) {
      throw Error(where(file, a), "open_angle must be a number (rad)");
    }
    if (!std::isfinite(o.open_angle)) throw Error(where(file, a), "open_angle must be finite");
  }
  const fs::path dir = fs::path(file).parent_path();
  ObjectLoadReport r;
  o.top = load_part((dir / text("top", true)).string(), scale, to_canonical, r.top);
  o.bottom = load_part((dir / text("bottom", true)).string(), scale, to_canonical, r.bottom);
  o.units_note = fs::path(file).filename().string() + " (" + units + ")";
  if (report) *report = r;
  return o;
}

ArticulatedObject load_arctic_object(const std::string& dir, ObjectLoadReport* report) {
  const fs::path d(dir);
  for (const char* part : {"top.obj", "bottom.obj"})
    if (!fs::is_regular_file(d / part))
      throw Error(dir + ": not an ARCTIC template folder (missing " + part + ")");
  ArticulatedObject o;
  o.name = fs::absolute(d).lexically_normal().filename().string();
  if (o.name.empty()) o.name = fs::absolute(d).lexically_normal().parent_path().filename().string();
  o.category = o.name;  // ARCTIC folders are named by category (box, laptop, ...)
  category_defaults(o);
  ObjectLoadReport r;
  const Eigen::Isometry3d id = Eigen::Isometry3d::Identity();
  o.top = load_part((d / "top.obj").string(), 0.001, id, r.top);
  o.bottom = load_part((d / "bottom.obj").string(), 0.001, id, r.bottom);
  o.units_note = "ARCTIC template (mm)";
  if (report) *report = r;
  return o;
}

ArticulatedObject load_object(const std::string& path, ObjectLoadReport* report) {
  const fs::path p(path);
  if (fs::is_directory(p)) {
    if (fs::is_regular_file(p / "object.yaml")) return load_object_yaml((p / "object.yaml").string(), report);
    return load_arctic_object(path, report);
  }
  if (!fs::exists(p)) throw Error(path + ": no such object file or folder");
  return load_object_yaml(path, report);
}

void write_obj(const TriangleMesh& mesh, const std::string& path) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# bimart object part, metres\n";
    for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
      out << fmt::format("v {:.17g} {:.17g} {:.17g}\n", mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2));
    for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
      out << fmt::format("f {} {} {}\n", mesh.faces(f, 0) + 1, mesh.faces(f, 1) + 1, mesh.faces(f, 2) + 1);
  });
}

void save_object(const ArticulatedObject& object, const std::string& dir) {
  const fs::path d(dir);
  write_obj(object.top, (d / "top.obj").string());
  write_obj(object.bottom, (d / "bottom.obj").string());
  YAML::Emitter y;
  y.SetDoublePrecision(17);
  y << YAML::BeginMap;
  y << YAML::Key << "name" << YAML::Value << object.name;
  if (!object.category.empty()) y << YAML::Key << "category" << YAML::Value << object.category;
  y << YAML::Key << "top" << YAML::Value << "top.obj";
  y << YAML::Key << "bottom" << YAML::Value << "bottom.obj";
  y << YAML::Key << "units" << YAML::Value << "m";
  y << YAML::Key << "limits" << YAML::Value << YAML::Flow << YAML::BeginSeq << object.angle_min << object.angle_max
    << YAML::EndSeq;
  y << YAML::Key << "open_angle" << YAML::Value << object.open_angle;
  y << YAML::EndMap;
  write_file_atomically((d / "object.yaml").string(), [&](std::ostream& out) {
    out << "# bimart articulated object: canonical frame, hinge = -z through the origin (docs/objects.md)\n"
        << y.c_str() << "\n";
  });
}

}  // namespace bimart
