#include "core/render/rasterizer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <cmath>
#include <fstream>

#include "core/util/error.h"

namespace bimart {
namespace {

// A square in the plane z = `z`, facing +z, with half-size `h`.
TriangleMesh square(double h, double z) {
  TriangleMesh m;
  m.vertices.resize(4, 3);
  m.vertices << -h, -h, z, h, -h, z, h, h, z, -h, h, z;
  m.faces.resize(2, 3);
  m.faces << 0, 1, 2, 0, 2, 3;
  return m;
}

bool is_background(const Image& im, int x, int y) {
  const auto* p = &im.rgb[(static_cast<std::size_t>(y) * im.width + x) * 3];
  return p[0] == 255 && p[1] == 255 && p[2] == 255;
}

Eigen::Vector3i pixel(const Image& im, int x, int y) {
  const auto* p = &im.rgb[(static_cast<std::size_t>(y) * im.width + x) * 3];
  return {p[0], p[1], p[2]};
}

TEST(Rasterizer, CubeFromPlusZCoversItsProjectedFrontFaceAndIsShaded) {
  const TriangleMesh cube = make_box(Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5));
  Camera cam;
  cam.eye = {0, 0, 3};
  cam.fov_deg = 35;
  const Image im = render({{&cube, {0.2, 0.4, 0.8}}}, cam, 200, 200);
  ASSERT_EQ(im.width, 200);
  ASSERT_EQ(im.height, 200);
  ASSERT_EQ(im.rgb.size(), 200u * 200u * 3u);
  int covered = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) covered += !is_background(im, x, y);
  // Only the front face (z = 0.5, 2.5 m away) is visible: side = 2 * focal * 0.5 / 2.5 px.
  const double focal = 100.0 / std::tan(17.5 * M_PI / 180.0);
  const double side = 2.0 * focal * 0.5 / 2.5;  // 126.9 px
  EXPECT_NEAR(covered / 40000.0, side * side / 40000.0, 0.01);

  // Centre: the smooth normal nearly faces the head light (the area-weighted corner normals
  // are not exactly symmetric), so nearly full brightness. Near a corner the normals tilt
  // away: darker, but above ambient (0.25).
  const Eigen::Vector3i centre = pixel(im, 100, 100);
  EXPECT_GT(centre[2], 0.93 * 0.8 * 255);
  EXPECT_LE(centre[2], 0.8 * 255 + 1);
  const int corner = static_cast<int>(100 - side / 2 + 3);
  const Eigen::Vector3i near_corner = pixel(im, corner, corner);
  EXPECT_LT(near_corner[2], centre[2] - 40);
  EXPECT_GT(near_corner[2], 0.25 * 0.8 * 255);
}

TEST(Rasterizer, NearerTrianglesOccludeFartherOnesWhateverTheOrder) {
  const TriangleMesh near_sq = square(0.2, 0.5), far_sq = square(0.6, -0.5);
  Camera cam;
  cam.eye = {0, 0, 3};
  for (bool near_first : {true, false}) {
    std::vector<RenderItem> items{{&near_sq, {1, 0, 0}}, {&far_sq, {0, 1, 0}}};
    if (!near_first) std::swap(items[0], items[1]);
    const Image im = render(items, cam, 100, 100);
    const Eigen::Vector3i c = pixel(im, 50, 50);
    EXPECT_GE(c[0], 253) << "near_first " << near_first;  // flat, facing the light: unshaded
    EXPECT_EQ(c[1], 0);
    // Outside the near square but inside the far one: the far square shows.
    const Eigen::Vector3i side = pixel(im, 50, 30);
    EXPECT_EQ(side[0], 0);
    EXPECT_GT(side[1], 200);
  }
}

TEST(Rasterizer, FrameItemsFitsTheSceneInView) {
  const TriangleMesh box = make_box({1, 2, 3}, {1.5, 2.1, 3.8});
  const Camera cam = frame_items({{&box, {0.5, 0.5, 0.5}}}, Eigen::Vector3d(1, -1, -1));
  EXPECT_TRUE(cam.target.isApprox(Eigen::Vector3d(1.25, 2.05, 3.4)));
  const Image im = render({{&box, {0.5, 0.5, 0.5}}}, cam, 120, 120);
  int covered = 0;
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 120; ++x) {
      const bool border = x == 0 || y == 0 || x == 119 || y == 119;
      if (border) EXPECT_TRUE(is_background(im, x, y)) << x << "," << y;
      covered += !is_background(im, x, y);
    }
  EXPECT_GT(covered, 500);
}

TEST(Rasterizer, PngHasTheImageSizeInItsHeader) {
  const TriangleMesh cube = make_box(Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5));
  const Image a = render({{&cube, {1, 0.5, 0}}}, frame_items({{&cube, {}}}, {0, 0, -1}), 64, 48);
  const Image b = render({{&cube, {1, 0.5, 0}}}, frame_items({{&cube, {}}}, {-1, -1, -1}), 40, 30);
  const Image t = tile({a, b, a}, 2);
  EXPECT_EQ(t.width, 128);
  EXPECT_EQ(t.height, 96);
  const std::string path = (std::filesystem::temp_directory_path() / "bimart_render_test.png").string();
  t.save_png(path);
  std::ifstream in(path, std::ios::binary);
  unsigned char h[24];
  in.read(reinterpret_cast<char*>(h), 24);
  ASSERT_TRUE(in);
  const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_TRUE(std::equal(sig, sig + 8, h));
  EXPECT_EQ(std::string(reinterpret_cast<char*>(h + 12), 4), "IHDR");
  auto be32 = [&](int o) { return (h[o] << 24) | (h[o + 1] << 16) | (h[o + 2] << 8) | h[o + 3]; };
  EXPECT_EQ(be32(16), 128);
  EXPECT_EQ(be32(20), 96);
  std::filesystem::remove(path);
}

TEST(Rasterizer, RejectsEmptyImages) {
  EXPECT_THROW(Image{}.save_png("/tmp/never.png"), Error);
  EXPECT_THROW(tile({}, 2), Error);
}

}  // namespace
}  // namespace bimart
