// Loaders that accepted wrong data silently: npz CRCs, duplicate YAML keys, degenerate
// object parts; and write errors that named the temporary file.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "core/io/npz.h"
#include "core/object/object_io.h"
#include "core/pipeline/graph.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/yaml_keys.h"
#include "tests/robust/fixture.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart {
namespace {

using test::ScratchDir;

TEST(NpzCrc, FlippedBytesInAStoredMemberAreRefused) {
  ScratchDir dir("crc");
  NpzFile npz;
  std::vector<double> v(64);
  for (size_t i = 0; i < v.size(); ++i) v[i] = 0.25 * static_cast<double>(i);
  npz.set("values", make_npy(v));
  const std::string path = dir / "a.npz";
  npz.write(path, NpzCompression::Store);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // The last value's bytes, inside the stored member (its data ends before the central directory).
  const double last = v.back();
  const size_t at = bytes.find(std::string(reinterpret_cast<const char*>(&last), 8));
  ASSERT_NE(at, std::string::npos);
  bytes[at + 3] ^= 0x10;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  const std::string e = error_of([&] { NpzFile::read(path); });
  EXPECT_NE(e.find("array 'values': corrupt member (CRC-32"), std::string::npos) << e;  // was read as valid data
}

TEST(NpzSizes, DeclaredMemberSizesAreBoundedByTheFile) {
  // Found by fuzzing: a 3 KB archive whose directory declares a 3 GB member, allocated at once.
  const std::string file = std::string(BIMART_SOURCE_DIR) + "/tests/fuzz/regressions/sequence/oom_declared_member_size.npz";
  const std::string e = error_of([&] { NpzFile::read(file); });
  EXPECT_NE(e.find("more than its 2977 bytes can hold"), std::string::npos) << e;
}

TEST(YamlKeys, DuplicateKeysAreErrorsNamingBothLines) {
  const std::string block =
      "name: dup\n"
      "stages:\n"
      "  - id: trajectory\n"
      "    use: trajectory.constant\n"
      "    params:\n"
      "      frames: 10\n"
      "      frames: 20\n";
  const std::string e = error_of([&] { GraphFile::parse(block, "p.yaml", ""); });
  EXPECT_NE(e.find("p.yaml:7:7: key 'frames' is given twice (first at line 6)"), std::string::npos) << e;
  const std::string flow = "name: dup\nstages:\n  - {id: a, use: trajectory.constant, id: b}\n";
  const std::string f = error_of([&] { GraphFile::parse(flow, "q.yaml", ""); });
  EXPECT_NE(f.find("q.yaml:3:39: key 'id' is given twice (first at line 3)"), std::string::npos) << f;
  // Found by fuzzing: the duplicate check looped forever on this input.
  EXPECT_NO_THROW(check_duplicate_keys(",ame:", "t.yaml"));
  // The same key in two different maps is fine.
  EXPECT_NO_THROW(GraphFile::parse("stages:\n  - {id: a, use: x.y}\n  - {id: b, use: x.y}\n", "r.yaml", ""));
}

TEST(YamlKeys, DuplicateKeysInAnObjectFile) {
  ScratchDir dir("object_dup");
  save_object(make_object("box", 1), dir / "box");
  test::write_text(dir / "box/object.yaml", "name: box\ntop: top.obj\nbottom: bottom.obj\nunits: m\nunits: mm\n");
  const std::string e = error_of([&] { load_object(dir / "box"); });
  EXPECT_NE(e.find("object.yaml:5:1: key 'units' is given twice (first at line 4)"), std::string::npos) << e;
}

// An object folder whose top part is `top` (OBJ text) and bottom part a real box.
std::string object_with_top(const ScratchDir& dir, const std::string& top) {
  save_object(make_object("box", 1), dir / "obj");
  test::write_text(dir / "obj/top.obj", top);
  return dir / "obj";
}

TEST(DegenerateParts, OneTriangleIsNoSolidPart) {
  ScratchDir dir("one_triangle");
  const std::string o = object_with_top(dir, "v 0 0 0\nv -0.1 0 0\nv 0 0.1 0\nf 1 2 3\n");
  const std::string e = error_of([&] { load_object(o); });  // was reported "closed"
  EXPECT_NE(e.find("top.obj: the part has 2 faces once closed"), std::string::npos) << e;
}

TEST(DegenerateParts, FlatSheetHasNoVolume) {
  ScratchDir dir("flat");
  // A closed tetrahedron whose fourth corner lies in the plane of the other three.
  const std::string o = object_with_top(
      dir, "v 0 0 0\nv -0.1 0 0\nv 0 0.1 0\nv -0.03 0.03 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
  const std::string e = error_of([&] { load_object(o); });
  EXPECT_NE(e.find("encloses"), std::string::npos) << e;
  EXPECT_NE(e.find("about zero"), std::string::npos) << e;
}

TEST(DegenerateParts, PartFarFromTheHingeIsRefusedWithTheDistance) {
  ScratchDir dir("far");
  // A 10 cm tetrahedron 500 m away along x.
  const std::string o = object_with_top(
      dir, "v 500 0 0\nv 500.1 0 0\nv 500 0.1 0\nv 500 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  const std::string e = error_of([&] { load_object(o); });
  EXPECT_NE(e.find("the part is 500 m from the hinge"), std::string::npos) << e;
}

TEST(DegenerateParts, EveryProceduralCategoryStillLoads) {
  ScratchDir dir("families");
  for (const std::string& c : object_categories())
    for (std::uint64_t seed : {0u, 1u, 2u}) {
      save_object(make_object(c, seed), dir / c);
      EXPECT_NO_THROW(load_object(dir / c)) << c << " seed " << seed;
    }
}

TEST(AtomicFile, ErrorsNameTheFinalPathNotTheTemporary) {
  ScratchDir dir("atomic");
  test::write_text(dir / "file", "x");
  const std::string target = dir / "file/sub/out.json";  // parent is a file
  const std::string e = error_of([&] { write_file_atomically(target, [](std::ostream& o) { o << 1; }); });
  EXPECT_NE(e.find("cannot write " + target), std::string::npos) << e;
  EXPECT_EQ(e.find(".tmp-"), std::string::npos) << e;
}

}  // namespace
}  // namespace bimart
