// Mesh files with one fault each: every fault gets its own message naming the file and the
// line, instead of one "cannot read mesh"; headers cannot make the reader allocate at will.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/object/mesh_repair.h"
#include "core/util/error.h"
#include "tests/robust/fixture.h"

namespace bimart {
namespace {

using test::ScratchDir;

// The message of reading `text` as a mesh file named `name`.
std::string read_error(const ScratchDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir / name;
  test::write_text(path, text);
  try {
    read_mesh_file(path);
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("other exception: ") + e.what();
  }
  return "";
}

const char* kTetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST(MeshFiles, ObjFaultsEachNameTheFaultAndLine) {
  ScratchDir dir("obj");
  EXPECT_EQ(read_error(dir, "ok.obj", kTetra), "");
  const std::string p = dir / "";
  EXPECT_EQ(read_error(dir, "empty.obj", ""), p + "empty.obj: the file is empty");
  EXPECT_EQ(read_error(dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
            p + "nan.obj:2: vertex coordinate 'nan' is not a finite number");
  EXPECT_EQ(read_error(dir, "inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n"),
            p + "inf.obj:3: vertex coordinate 'inf' is not a finite number");
  EXPECT_EQ(read_error(dir, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
            p + "range.obj:4: face index 9 refers to vertex 9, but only 3 vertices come before it");
  EXPECT_EQ(read_error(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
            p + "zero.obj:4: face index 0: OBJ indices start at 1 (or count back from -1)");
  EXPECT_EQ(read_error(dir, "nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
            p + "nofaces.obj: 3 vertices but no faces ('f' lines): a point cloud is no mesh");
  EXPECT_EQ(read_error(dir, "garbage.obj", std::string("v 0 0 0\n\x01\x02\xff\x00\x13", 13)),
            p + "garbage.obj:2: binary bytes in a text OBJ file (damaged, or not OBJ?)");
  // Negative (relative) indices are valid OBJ.
  EXPECT_EQ(read_error(dir, "relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"), "");
}

TEST(MeshFiles, OffHeaderCannotAskForBillionsOfVertices) {
  ScratchDir dir("off");
  const std::string p = dir / "";
  EXPECT_EQ(read_error(dir, "ok.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"), "");
  // Was std::bad_alloc.
  EXPECT_EQ(read_error(dir, "huge.off", "OFF\n2000000000 1 0\n0 0 0\n"),
            p + "huge.off:2: the header declares 2000000000 vertices, but the file has only 25 bytes (truncated or "
                "damaged)");
  EXPECT_EQ(read_error(dir, "range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
            p + "range.off:6: face index 3 is out of range [0, 3)");
  EXPECT_EQ(read_error(dir, "short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), p + "short.off:4: ends after 2 of 3 vertices");
  EXPECT_EQ(read_error(dir, "bad.off", "PFF\n3 1 0\n"), p + "bad.off:1: the first line must be 'OFF' (got 'PFF')");
}

TEST(MeshFiles, PlyAndStlHeadersAreChecked) {
  ScratchDir dir("ply");
  const std::string p = dir / "";
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(read_error(dir, "ok.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "");
  EXPECT_EQ(read_error(dir, "nan.ply", head + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
            p + "nan.ply:11: vertex coordinate 'nan' is not a finite number");
  EXPECT_EQ(read_error(dir, "range.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
            p + "range.ply:13: face index 7 is out of range [0, 3)");
  EXPECT_EQ(read_error(dir, "huge.ply",
                       "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
                       "property float y\nproperty float z\nend_header\n"),
            p + "huge.ply:7: the header declares 1000000000 vertex elements, but the file has only 124 bytes "
                "(truncated or damaged)");
  // Binary STL: the triangle count must match the size.
  std::string stl(84, '\0');
  const std::uint32_t count = 100000000;
  std::memcpy(&stl[80], &count, 4);
  EXPECT_EQ(read_error(dir, "huge.stl", stl),
            p + "huge.stl: the header declares 100000000 triangles (5000000084 bytes), but the file has 84 bytes");
}

// Binary PLY, as our reader reads it (CGAL's crashed on fuzzed PLY files): both byte
// orders give the same tetrahedron; extra properties are read past; a negative or oversized
// list count, a truncated body and a missing face list each name their fault.
std::string binary_ply(bool big, const std::string& face_props, const std::string& body_faces, int vertices = 4) {
  std::string s = std::string("ply\nformat binary_") + (big ? "big" : "little") + "_endian 1.0\nelement vertex " +
                  std::to_string(vertices) + "\nproperty float x\nproperty float y\nproperty float z\n" +
                  "property uchar flag\nelement face 4\n" + face_props + "end_header\n";
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < vertices; ++i) {
    for (float x : v[i]) {
      char b[4];
      std::memcpy(b, &x, 4);
      if (big) std::reverse(b, b + 4);
      s.append(b, 4);
    }
    s.push_back('\x07');  // flag
  }
  return s + body_faces;
}

std::string faces_u8_i32(bool big, const std::vector<std::vector<std::int32_t>>& faces, char extra = 0) {
  std::string s;
  for (const auto& f : faces) {
    s.push_back(extra);
    s.push_back(static_cast<char>(f.size()));
    for (std::int32_t id : f) {
      char b[4];
      std::memcpy(b, &id, 4);
      if (big) std::reverse(b, b + 4);
      s.append(b, 4);
    }
  }
  return s;
}

TEST(MeshFiles, BinaryPlyInBothByteOrdersAndItsFaults) {
  ScratchDir dir("ply_binary");
  const std::string p = dir / "";
  const std::vector<std::vector<std::int32_t>> tetra = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const std::string props = "property uchar red\nproperty list uchar int vertex_indices\n";
  for (bool big : {false, true}) {
    const std::string name = big ? "be.ply" : "le.ply";
    EXPECT_EQ(read_error(dir, name, binary_ply(big, props, faces_u8_i32(big, tetra))), "");
    const TriangleMesh m = read_mesh_file(dir / name);
    ASSERT_EQ(m.num_vertices(), 4);
    ASSERT_EQ(m.num_faces(), 4);
    EXPECT_EQ(m.vertices(3, 2), 1.0);
    EXPECT_EQ(m.faces(3, 1), 2);
  }
  EXPECT_EQ(read_error(dir, "range.ply", binary_ply(false, props, faces_u8_i32(false, {{0, 2, 1}, {0, 1, 9}}))),
            p + "range.ply: byte 284: face index 9 is out of range [0, 4)");
  EXPECT_EQ(read_error(dir, "short.ply", binary_ply(false, props, faces_u8_i32(false, {{0, 2, 1}}))),
            p + "short.ply: byte 274: the file ends where a number was expected (truncated)");
  // A signed count of -1: CGAL would size a list from it.
  const std::string signed_props = "property uchar red\nproperty list char int vertex_indices\n";
  std::string neg = faces_u8_i32(false, tetra);
  neg[1] = '\xff';
  EXPECT_EQ(read_error(dir, "negative.ply", binary_ply(false, signed_props, neg)),
            p + "negative.ply: byte 260: a list of -1 items does not fit in the rest of the file");
  EXPECT_EQ(read_error(dir, "nolist.ply", binary_ply(false, "property list uchar int corners\n", faces_u8_i32(false, tetra))),
            p + "nolist.ply:8: the faces have no list property 'vertex_indices' (or 'vertex_index')");
  EXPECT_EQ(read_error(dir, "floatcount.ply", binary_ply(false, "property list float int vertex_indices\n", "")),
            p + "floatcount.ply:9: a list's count type must be an integer type, not 'float'");
}

}  // namespace
}  // namespace bimart
