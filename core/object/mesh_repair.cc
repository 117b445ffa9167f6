#include "core/object/mesh_repair.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <fmt/format.h>
#include <vector>

#include "core/object/mesh_file_check.h"
#include "core/object/ply_file.h"
#include "core/util/error.h"

namespace bimart {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;
namespace fs = std::filesystem;

TriangleMesh from_surface_mesh(Mesh& sm) {
  sm.collect_garbage();
  TriangleMesh m;
  m.vertices.resize(sm.number_of_vertices(), 3);
  for (Mesh::Vertex_index v : sm.vertices()) {
    const Point& p = sm.point(v);
    m.vertices.row(v.idx()) << p.x(), p.y(), p.z();
  }
  m.faces.resize(sm.number_of_faces(), 3);
  Eigen::Index i = 0;
  for (Mesh::Face_index f : sm.faces()) {
    int c = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) m.faces(i, c++) = static_cast<int>(v.idx());
    ++i;
  }
  return m;
}

// Flips every connected component (faces sharing vertices) whose signed volume is negative;
// returns how many were flipped. Hand-written because CGAL 5.5's orient_to_bound_a_volume
// crashed here (segfault in volume_connected_components) on meshes just filled by
// triangulate_and_refine_hole; unlike it, this
// does not treat nested shells (a cavity inside a part) as inward-facing.
int orient_components_outward(TriangleMesh& m) {
  std::vector<int> parent(static_cast<std::size_t>(m.num_vertices()));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[static_cast<std::size_t>(v)] != v) v = parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    return v;
  };
  for (Eigen::Index f = 0; f < m.num_faces(); ++f)
    for (int c = 1; c < 3; ++c) parent[static_cast<std::size_t>(find(m.faces(f, c)))] = find(m.faces(f, 0));
  std::map<int, double> volume;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    volume[find(m.faces(f, 0))] += a.dot(b.cross(c));
  }
  int flipped = 0;
  for (const auto& [root, v] : volume) flipped += v < 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f)
    if (volume[find(m.faces(f, 0))] < 0) std::swap(m.faces(f, 1), m.faces(f, 2));
  return flipped;
}

}  // namespace

TriangleMesh read_mesh_file(const std::string& path) {
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (ext == ".ply") {  // our reader: CGAL's crashed on fuzzed PLY files (core/object/ply_file.h)
    PlyMesh ply = read_ply_file(path);
    for (const auto& v : ply.vertices) points.emplace_back(v[0], v[1], v[2]);
    for (const auto& f : ply.faces) polygons.emplace_back(f.begin(), f.end());
  } else {
    check_mesh_file(path);  // names the fault and the line; bounds what headers declare
    bool ok = false;
    try {
      ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
    } catch (const std::exception& e) {
      throw Error(path + ": cannot read mesh: " + e.what());
    }
    if (!ok) throw Error(path + ": cannot read mesh (supported: .obj, .ply, .off, .stl)");
  }
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    m.vertices.row(static_cast<Eigen::Index>(i)) << points[i].x(), points[i].y(), points[i].z();
  std::vector<std::array<int, 3>> tris;
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& p = polygons[f];
    if (p.size() < 3) throw Error(fmt::format("{}: face {} has {} corners", path, f, p.size()));
    for (std::size_t k = 1; k + 1 < p.size(); ++k)
      tris.push_back({static_cast<int>(p[0]), static_cast<int>(p[k]), static_cast<int>(p[k + 1])});
  }
  m.faces.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t f = 0; f < tris.size(); ++f)
    m.faces.row(static_cast<Eigen::Index>(f)) << tris[f][0], tris[f][1], tris[f][2];
  return m;
}

double bounding_radius(const TriangleMesh& mesh) {
  if (mesh.num_vertices() == 0) return 0;
  return 0.5 * (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();
}

void validate_mesh(const TriangleMesh& mesh, const std::string& file) {
  if (mesh.num_vertices() == 0 || mesh.num_faces() == 0)
    throw Error(fmt::format("{}: the mesh is empty ({} vertices, {} faces)", file, mesh.num_vertices(),
                            mesh.num_faces()));
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    if (!mesh.vertices.row(i).allFinite())
      throw Error(fmt::format("{}: vertex {} has a non-finite coordinate", file, i));
  const double r = bounding_radius(mesh);
  const double min_area = 1e-12 * r * r;  // relative: zero up to rounding
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c)
      if (mesh.faces(f, c) < 0 || mesh.faces(f, c) >= mesh.num_vertices())
        throw Error(fmt::format("{}: face {} uses vertex {}, but there are {} vertices", file, f, mesh.faces(f, c),
                                mesh.num_vertices()));
    const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0));
    const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1));
    const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2));
    if (!(0.5 * (b - a).cross(c - a).norm() > min_area))
      throw Error(fmt::format("{}: face {} is degenerate (zero area)", file, f));
  }
}

std::string RepairReport::str() const {
  if (!changed()) return "closed and outward, nothing repaired";
  std::string s = fmt::format("filled {} hole{} (+{} faces, +{} vertices)", holes_filled, holes_filled == 1 ? "" : "s",
                              faces_added, vertices_added);
  if (reoriented) s = (holes_filled > 0 ? s + ", " : "") + "flipped faces outwards";
  return s;
}

RepairReport close_and_orient(TriangleMesh& mesh, const std::string& file) {
  std::vector<Point> points;
  points.reserve(mesh.num_vertices());
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    points.emplace_back(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2));
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(mesh.num_faces());
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    polygons.push_back({static_cast<std::size_t>(mesh.faces(f, 0)), static_cast<std::size_t>(mesh.faces(f, 1)),
                        static_cast<std::size_t>(mesh.faces(f, 2))});
  // Consistent orientation first (duplicates vertices where the soup is not a manifold).
  PMP::orient_polygon_soup(points, polygons);
  Mesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);

  RepairReport report;
  const std::size_t faces_before = sm.number_of_faces();
  report.vertices_added = static_cast<int>(sm.number_of_vertices()) - static_cast<int>(mesh.num_vertices());

  std::vector<Mesh::Halfedge_index> cycles;
  PMP::extract_boundary_cycles(sm, std::back_inserter(cycles));
  for (Mesh::Halfedge_index h : cycles) {
    std::vector<Mesh::Face_index> new_faces;
    std::vector<Mesh::Vertex_index> new_vertices;
    PMP::triangulate_and_refine_hole(sm, h, std::back_inserter(new_faces), std::back_inserter(new_vertices));
    if (new_faces.empty()) throw Error(fmt::format("{}: could not fill a hole of the mesh", file));
    report.vertices_added += static_cast<int>(new_vertices.size());
    ++report.holes_filled;
  }
  if (!CGAL::is_closed(sm))
    throw Error(fmt::format("{}: the mesh is still open after filling {} holes", file, report.holes_filled));
  report.faces_added = static_cast<int>(sm.number_of_faces() - faces_before);

  mesh = from_surface_mesh(sm);
  if (!mesh.vertices.allFinite()) throw Error(fmt::format("{}: filling the holes gave non-finite vertices", file));
  report.reoriented = orient_components_outward(mesh) > 0;
  return report;
}

bool is_closed_mesh(const TriangleMesh& mesh) {
  if (mesh.num_faces() == 0) return false;
  Mesh sm;
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    sm.add_vertex(Point(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2)));
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
    if (a < 0 || b < 0 || c < 0 || a >= mesh.num_vertices() || b >= mesh.num_vertices() || c >= mesh.num_vertices())
      return false;
    if (sm.add_face(Mesh::Vertex_index(a), Mesh::Vertex_index(b), Mesh::Vertex_index(c)) == Mesh::null_face())
      return false;  // non-manifold or inconsistently oriented
  }
  return CGAL::is_closed(sm) && sm.is_valid(false);
}

double signed_volume(const TriangleMesh& mesh) {
  double v = 0;
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0));
    const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1));
    const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2));
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

}  // namespace bimart
