#include "core/geometry/mesh_distance.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/geometry/point_guard.h"
#include "core/util/error.h"

namespace bimart {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
using Side = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;
namespace PMP = CGAL::Polygon_mesh_processing;

}  // namespace

// One closed component of the mesh with its own tree, for the inside test and the depth.
struct Component {
  Mesh mesh;
  Tree tree;
  std::unique_ptr<Side> side;
};

// Meshes must outlive their trees (primitives refer to them), so everything lives here and
// the Impl is never moved once built (it sits behind the unique_ptr).
//
// A part may be a union of closed components that overlap (procedural parts append
// primitives; scanned parts may have separate handles). Ray parity over the whole mesh
// would call the overlap "outside", so the inside test runs per component: a point is
// inside when it is inside any component. Depth inside = the largest distance to the
// surface of a component holding the point (exact without overlaps, a lower bound with
// them); distance outside = distance to the nearest face of any component (exact).
struct MeshDistance::Impl {
  Mesh mesh;                    // all components
  Tree tree;                    // over all faces: the nearest surface point
  std::vector<int> face_index;  // Surface_mesh face -> input face row
  std::vector<std::unique_ptr<Component>> components;
  Eigen::Vector3d lo, hi;  // bounding box of all vertices

  void build_components(const std::vector<Point>& points,
                        const std::vector<std::array<std::size_t, 3>>& polygons);
};

void MeshDistance::Impl::build_components(const std::vector<Point>& points,
                                          const std::vector<std::array<std::size_t, 3>>& polygons) {
  // Components by shared vertices (union-find over face corners).
  std::vector<std::size_t> parent(points.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& t : polygons) {
    parent[find(t[1])] = find(t[0]);
    parent[find(t[2])] = find(t[0]);
  }
  std::vector<int> comp_of_root(points.size(), -1);
  std::vector<std::vector<std::array<std::size_t, 3>>> comp_polys;
  for (const auto& t : polygons) {
    const std::size_t r = find(t[0]);
    if (comp_of_root[r] < 0) {
      comp_of_root[r] = static_cast<int>(comp_polys.size());
      comp_polys.emplace_back();
    }
    comp_polys[static_cast<size_t>(comp_of_root[r])].push_back(t);
  }
  for (auto& polys : comp_polys) {
    auto c = std::make_unique<Component>();
    // Only this component's vertices, renumbered.
    std::vector<Point> pts;
    std::vector<std::size_t> remap(points.size(), static_cast<std::size_t>(-1));
    for (auto& t : polys)
      for (auto& v : t) {
        if (remap[v] == static_cast<std::size_t>(-1)) {
          remap[v] = pts.size();
          pts.push_back(points[v]);
        }
        v = remap[v];
      }
    PMP::orient_polygon_soup(pts, polys);
    PMP::polygon_soup_to_polygon_mesh(pts, polys, c->mesh);
    if (!CGAL::is_closed(c->mesh))
      throw Error("MeshDistance: the mesh is not closed (it has border edges); inside tests need "
                  "closed meshes (see core/object/mesh_repair.h close_and_orient)");
    c->tree.insert(faces(c->mesh).first, faces(c->mesh).second, c->mesh);
    c->tree.build();
    c->tree.accelerate_distance_queries();
    c->tree.closest_point(Point(0, 0, 0));
    c->side = std::make_unique<Side>(c->tree);
    components.push_back(std::move(c));
  }
}

MeshDistance::MeshDistance(const TriangleMesh& input) : impl_(std::make_unique<Impl>()) {
  if (input.num_vertices() == 0 || input.num_faces() == 0)
    throw Error("MeshDistance: the mesh is empty");
  std::vector<Point> points;
  points.reserve(static_cast<size_t>(input.num_vertices()));
  for (Eigen::Index i = 0; i < input.num_vertices(); ++i) {
    const auto v = input.vertices.row(i);
    check_point(v.transpose(), "MeshDistance: mesh vertex", i);
    points.emplace_back(v(0), v(1), v(2));
  }
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(static_cast<size_t>(input.num_faces()));
  for (Eigen::Index f = 0; f < input.num_faces(); ++f) {
    std::array<std::size_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const int idx = input.faces(f, k);
      if (idx < 0 || idx >= input.num_vertices())
        throw Error("MeshDistance: face " + std::to_string(f) + " has vertex index " +
                    std::to_string(idx) + " out of range");
      tri[static_cast<size_t>(k)] = static_cast<std::size_t>(idx);
    }
    polygons.push_back(tri);
  }
  impl_->build_components(points, polygons);
  impl_->lo = input.vertices.colwise().minCoeff().transpose();
  impl_->hi = input.vertices.colwise().maxCoeff().transpose();
  // The whole mesh, face for face in input order, for the nearest surface point. Through a
  // polygon soup so that components touching at a vertex or edge still give a valid
  // halfedge mesh (orienting the soup duplicates non-manifold vertices).
  PMP::orient_polygon_soup(points, polygons);
  PMP::polygon_soup_to_polygon_mesh(points, polygons, impl_->mesh);
  Mesh& m = impl_->mesh;
  if (static_cast<Eigen::Index>(m.number_of_faces()) != input.num_faces())
    throw Error("MeshDistance: the mesh could not be converted face for face (" +
                std::to_string(m.number_of_faces()) + " of " + std::to_string(input.num_faces()) +
                " faces)");
  impl_->face_index.resize(m.number_of_faces());
  int i = 0;
  for (auto f : m.faces()) impl_->face_index[static_cast<size_t>(f.idx())] = i++;
  impl_->tree.insert(faces(m).first, faces(m).second, m);
  impl_->tree.build();
  // Build the distance-query search structure now so that later const queries from
  // several threads never trigger a lazy build.
  impl_->tree.accelerate_distance_queries();
  impl_->tree.closest_point(Point(0, 0, 0));
}

MeshDistance::~MeshDistance() = default;
MeshDistance::MeshDistance(MeshDistance&&) noexcept = default;
MeshDistance& MeshDistance::operator=(MeshDistance&&) noexcept = default;

namespace {
// > 0: the depth inside the union of components; 0 on a surface; -1 outside all.
template <class Comps>
double depth_inside(const Comps& comps, const Point& q, const void** deepest) {
  double depth = -1;
  for (const auto& c : comps) {
    const CGAL::Bounded_side side = (*c->side)(q);
    if (side == CGAL::ON_UNBOUNDED_SIDE) continue;
    const double d = side == CGAL::ON_BOUNDARY ? 0.0 : std::sqrt(c->tree.squared_distance(q));
    if (d > depth) {
      depth = d;
      if (deepest) *deepest = c.get();
    }
  }
  return depth;
}
}  // namespace

SurfaceQuery MeshDistance::query(const Eigen::Vector3d& p) const {
  check_point(p, "surface query");
  const Point q(p.x(), p.y(), p.z());
  const auto hit = impl_->tree.closest_point_and_primitive(q);
  SurfaceQuery out;
  out.closest = Eigen::Vector3d(hit.first.x(), hit.first.y(), hit.first.z());
  out.face = impl_->face_index[static_cast<size_t>(hit.second.idx())];
  const void* deepest = nullptr;
  const double depth = depth_inside(impl_->components, q, &deepest);
  if (depth < 0) {
    out.signed_distance = -(out.closest - p).norm();
  } else {
    out.signed_distance = depth;
    if (deepest && impl_->components.size() > 1) {
      // The nearest point of the component that holds the point deepest.
      const Point c = static_cast<const Component*>(deepest)->tree.closest_point(q);
      out.closest = Eigen::Vector3d(c.x(), c.y(), c.z());
      const auto h = impl_->tree.closest_point_and_primitive(c);
      out.face = impl_->face_index[static_cast<size_t>(h.second.idx())];
    }
  }
  const Eigen::Vector3d d = p - out.closest;
  const double dn = d.norm();
  if (dn > 1e-9) {
    out.normal = (depth < 0 ? 1.0 : -1.0) * d / dn;
  } else {  // on the surface: the nearest face's normal, pointing out of the mesh
    const auto n = CGAL::Polygon_mesh_processing::compute_face_normal(hit.second, impl_->mesh);
    out.normal = Eigen::Vector3d(n.x(), n.y(), n.z()).normalized();
    const Eigen::Vector3d probe = out.closest + 1e-6 * out.normal;
    if (depth_inside(impl_->components, Point(probe.x(), probe.y(), probe.z()), nullptr) > 0)
      out.normal = -out.normal;
  }
  return out;
}

Eigen::AlignedBox3d MeshDistance::bounding_box() const { return Eigen::AlignedBox3d(impl_->lo, impl_->hi); }

double MeshDistance::signed_distance(const Eigen::Vector3d& p) const {
  check_point(p, "signed distance");
  const Point q(p.x(), p.y(), p.z());
  const double depth = depth_inside(impl_->components, q, nullptr);
  return depth >= 0 ? depth : -std::sqrt(impl_->tree.squared_distance(q));
}

bool MeshDistance::inside(const Eigen::Vector3d& p) const {
  check_point(p, "inside test");
  const Point q(p.x(), p.y(), p.z());
  for (const auto& c : impl_->components)
    if ((*c->side)(q) == CGAL::ON_BOUNDED_SIDE) return true;
  return false;
}

double MeshDistance::max_signed_distance(const Points3& points) const {
  check_points(points, "signed distance");
  double best = -std::numeric_limits<double>::infinity();
  const Eigen::Vector3d lo = impl_->lo, hi = impl_->hi;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d p = points.row(i).transpose();
    const Point q(p.x(), p.y(), p.z());
    const Eigen::Vector3d gap = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
    const double outside_box = gap.norm();
    if (outside_box > 0) {
      // Outside the box, so outside the mesh, at least this far from it.
      if (-outside_box <= best) continue;
      best = std::max(best, -std::sqrt(impl_->tree.squared_distance(q)));
      continue;
    }
    // Inside the box: the depth (if inside) is at most the distance to the box's faces;
    // if outside, the signed distance is < 0 <= that bound.
    const double depth_bound = (p - lo).cwiseMin(hi - p).minCoeff();
    if (depth_bound <= best) continue;
    const double depth = depth_inside(impl_->components, q, nullptr);
    if (depth >= 0) {
      best = std::max(best, depth);
    } else if (best < 0) {
      best = std::max(best, -std::sqrt(impl_->tree.squared_distance(q)));
    }
  }
  return best;
}

bool MeshDistance::any_deeper_than(const Points3& points, double threshold) const {
  check_points(points, "depth test");
  const Eigen::Vector3d lo = impl_->lo, hi = impl_->hi;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d p = points.row(i).transpose();
    // Deeper than `threshold` needs a point at least that far inside the bounding box.
    if ((p - lo).cwiseMin(hi - p).minCoeff() <= threshold) continue;
    if (depth_inside(impl_->components, Point(p.x(), p.y(), p.z()), nullptr) > threshold) return true;
  }
  return false;
}

int MeshDistance::num_components() const { return static_cast<int>(impl_->components.size()); }

Eigen::VectorXd MeshDistance::signed_distances(const Points3& points) const {
  Eigen::VectorXd out(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    out(i) = signed_distance(points.row(i).transpose());
  return out;
}

}  // namespace bimart
