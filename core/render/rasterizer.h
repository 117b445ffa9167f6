// A small CPU z-buffer rasterizer for pictures in docs and previews: perspective camera,
// per-pixel depth, smooth (area-weighted vertex) normals, Lambert + ambient shading from a
// light at the eye, 2x2 supersampling, PNG output. Not for interactive use.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

// One mesh to draw, in a flat colour (RGB in [0, 1]). The mesh must outlive the render call.
struct RenderItem {
  const TriangleMesh* mesh = nullptr;
  Eigen::Vector3d color{0.8, 0.8, 0.8};
};

// A pinhole camera at `eye` looking at `target`; fov_deg is the vertical field of view.
struct Camera {
  Eigen::Vector3d eye{0, 0, 1};
  Eigen::Vector3d target{0, 0, 0};
  Eigen::Vector3d up{0, 1, 0};
  double fov_deg = 35;
};

// Rows top to bottom, 3 bytes (R, G, B) per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  // Writes a PNG atomically (core/util/atomic_file.h); throws bimart::Error on failure.
  void save_png(const std::string& path) const;
};

struct RenderOptions {
  Eigen::Vector3d background{1, 1, 1};
  double ambient = 0.25;  // light that reaches every surface; the head light adds the rest
  int supersample = 2;    // samples per pixel along each axis
};

// A camera that looks along `view_dir` (from the eye towards the scene) at the centre of
// the items' bounding box, far enough that their bounding sphere fits the vertical field of
// view (so the whole view when the image is at least as wide as high). Its `up`
// is +y unless view_dir is nearly parallel to y, then -z.
Camera frame_items(const std::vector<RenderItem>& items, const Eigen::Vector3d& view_dir, double fov_deg = 35);

// Square pixels; the vertical extent follows the camera's fov. Triangles with a vertex
// behind the near plane (1 mm in front of the eye) are skipped rather than clipped.
Image render(const std::vector<RenderItem>& items, const Camera& camera, int width, int height,
             const RenderOptions& options = {});

// Lays images out left to right, top to bottom, `columns` per row; every cell is as large
// as the largest image, and images are centred in their cells on a white background.
Image tile(const std::vector<Image>& images, int columns);

}  // namespace bimart
