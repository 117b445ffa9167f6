#include "core/render/rasterizer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>

#include "core/util/atomic_file.h"
#include "core/util/error.h"

namespace bimart {

namespace {

constexpr double kNear = 1e-3;  // metres in front of the eye

std::uint8_t to_byte(double c) { return static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0)); }

}  // namespace

void Image::save_png(const std::string& path) const {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3)
    throw Error("cannot write " + path + ": image is empty or its pixel buffer has the wrong size");
  std::string png;
  auto append = [](void* ctx, void* data, int size) {
    static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, width, height, 3, rgb.data(), width * 3))
    throw Error("cannot encode " + path + " as PNG");
  write_file_atomically(path, [&](std::ostream& out) { out.write(png.data(), static_cast<std::streamsize>(png.size())); });
}

Camera frame_items(const std::vector<RenderItem>& items, const Eigen::Vector3d& view_dir, double fov_deg) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& it : items)
    for (Eigen::Index v = 0; v < it.mesh->num_vertices(); ++v) {
      lo = lo.cwiseMin(it.mesh->vertices.row(v).transpose());
      hi = hi.cwiseMax(it.mesh->vertices.row(v).transpose());
    }
  if (!(lo.array() <= hi.array()).all()) throw Error("frame_items: nothing to frame (no vertices)");
  if (view_dir.norm() == 0) throw Error("frame_items: view direction is zero");
  const Eigen::Vector3d center = 0.5 * (lo + hi);
  double radius = 0;
  for (const auto& it : items)
    for (Eigen::Index v = 0; v < it.mesh->num_vertices(); ++v)
      radius = std::max(radius, (it.mesh->vertices.row(v).transpose() - center).norm());
  radius = std::max(radius, 1e-6);
  const Eigen::Vector3d d = view_dir.normalized();
  Camera cam;
  cam.fov_deg = fov_deg;
  const double half = 0.5 * fov_deg * M_PI / 180.0;
  cam.target = center;
  cam.eye = center - d * (1.05 * radius / std::sin(half));
  cam.up = std::abs(d.y()) > 0.99 ? Eigen::Vector3d(0, 0, -1) : Eigen::Vector3d(0, 1, 0);
  return cam;
}

Image render(const std::vector<RenderItem>& items, const Camera& camera, int width, int height,
             const RenderOptions& options) {
  if (width <= 0 || height <= 0) throw Error("render: image size must be positive");
  const int s = std::max(1, options.supersample);
  const int W = width * s, H = height * s;
  const Eigen::Vector3d fwd = (camera.target - camera.eye).normalized();
  const Eigen::Vector3d right = fwd.cross(camera.up).normalized();
  const Eigen::Vector3d up = right.cross(fwd);
  if (!fwd.allFinite() || !right.allFinite()) throw Error("render: camera eye, target and up are degenerate");
  const double focal = 0.5 * H / std::tan(0.5 * camera.fov_deg * M_PI / 180.0);

  std::vector<double> depth(static_cast<std::size_t>(W) * H, std::numeric_limits<double>::infinity());
  std::vector<Eigen::Vector3f> color(static_cast<std::size_t>(W) * H, options.background.cast<float>());

  for (const auto& item : items) {
    const TriangleMesh& m = *item.mesh;
    const Eigen::MatrixX3d normals = vertex_normals(m);
    // Camera-space position and screen position of every vertex.
    const Eigen::Index nv = m.num_vertices();
    Eigen::MatrixX3d cam(nv, 3);
    for (Eigen::Index v = 0; v < nv; ++v) {
      const Eigen::Vector3d p = m.vertices.row(v).transpose() - camera.eye;
      cam.row(v) << p.dot(right), p.dot(up), p.dot(fwd);
    }
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      const int id[3] = {m.faces(f, 0), m.faces(f, 1), m.faces(f, 2)};
      double sx[3], sy[3], z[3];
      bool behind = false;
      for (int k = 0; k < 3; ++k) {
        z[k] = cam(id[k], 2);
        if (z[k] < kNear) behind = true;
        sx[k] = 0.5 * W + focal * cam(id[k], 0) / z[k];
        sy[k] = 0.5 * H - focal * cam(id[k], 1) / z[k];
      }
      if (behind) continue;
      const double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
      if (area == 0) continue;
      // A triangle seen from behind is shaded with its normals flipped (open meshes).
      const Eigen::Vector3d a = m.vertices.row(id[0]), b = m.vertices.row(id[1]), c = m.vertices.row(id[2]);
      const double facing = (b - a).cross(c - a).dot(camera.eye - a) >= 0 ? 1.0 : -1.0;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({sx[0], sx[1], sx[2]}))));
      const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({sy[0], sy[1], sy[2]}))));
      const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({sy[0], sy[1], sy[2]}))));
      for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
          const double qx = px + 0.5, qy = py + 0.5;
          // Screen-space barycentrics from edge functions, normalised by the signed area.
          double w[3];
          w[0] = ((sx[1] - qx) * (sy[2] - qy) - (sx[2] - qx) * (sy[1] - qy)) / area;
          w[1] = ((sx[2] - qx) * (sy[0] - qy) - (sx[0] - qx) * (sy[2] - qy)) / area;
          w[2] = 1.0 - w[0] - w[1];
          if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
          // Perspective-correct interpolation: weights over z, renormalised.
          const double iz = w[0] / z[0] + w[1] / z[1] + w[2] / z[2];
          const double d = 1.0 / iz;
          const std::size_t pix = static_cast<std::size_t>(py) * W + px;
          if (d >= depth[pix]) continue;
          depth[pix] = d;
          Eigen::Vector3d n = Eigen::Vector3d::Zero(), p = Eigen::Vector3d::Zero();
          for (int k = 0; k < 3; ++k) {
            const double wk = w[k] / z[k] * d;
            n += wk * normals.row(id[k]).transpose();
            p += wk * m.vertices.row(id[k]).transpose();
          }
          const double nn = n.norm();
          n = nn > 0 ? Eigen::Vector3d(facing * n / nn) : Eigen::Vector3d::Zero();
          const Eigen::Vector3d to_eye = (camera.eye - p).normalized();
          const double shade = options.ambient + (1.0 - options.ambient) * std::max(0.0, n.dot(to_eye));
          color[pix] = (item.color * shade).cast<float>();
        }
    }
  }

  // Box filter down to the output size.
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.resize(static_cast<std::size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) sum += color[static_cast<std::size_t>(y * s + j) * W + (x * s + i)];
      sum /= static_cast<float>(s * s);
      for (int k = 0; k < 3; ++k) img.rgb[(static_cast<std::size_t>(y) * width + x) * 3 + k] = to_byte(sum[k]);
    }
  return img;
}

Image tile(const std::vector<Image>& images, int columns) {
  if (images.empty()) throw Error("tile: no images");
  if (columns <= 0) throw Error("tile: columns must be positive");
  int cw = 0, ch = 0;
  for (const auto& im : images) {
    cw = std::max(cw, im.width);
    ch = std::max(ch, im.height);
  }
  const int n = static_cast<int>(images.size());
  const int cols = std::min(columns, n);
  const int rows = (n + cols - 1) / cols;
  Image out;
  out.width = cols * cw;
  out.height = rows * ch;
  out.rgb.assign(static_cast<std::size_t>(out.width) * out.height * 3, 255);
  for (int i = 0; i < n; ++i) {
    const Image& im = images[i];
    const int ox = (i % cols) * cw + (cw - im.width) / 2;
    const int oy = (i / cols) * ch + (ch - im.height) / 2;
    for (int y = 0; y < im.height; ++y)
      std::copy_n(im.rgb.begin() + static_cast<std::ptrdiff_t>(y) * im.width * 3, im.width * 3,
                  out.rgb.begin() + (static_cast<std::ptrdiff_t>(oy + y) * out.width + ox) * 3);
  }
  return out;
}

}  // namespace bimart
