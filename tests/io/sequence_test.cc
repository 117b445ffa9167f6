#include "core/io/sequence.h"

#include <gtest/gtest.h>

#include <filesystem>

#include <ATen/ATen.h>

#include "core/io/npz.h"
#include "core/util/error.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

Sequence make_sequence(int64_t n, bool vertices) {
  at::manual_seed(3);
  Sequence s;
  s.name = "box_s0001_use_001";
  s.object = "../objects/box_1";
  s.category = "box";
  s.kind = "use";
  s.fps = 30;
  s.object_states = at::randn({n, 7});
  for (auto& h : s.hands.hands) {
    h.rot = at::randn({n, 3});
    h.pose = at::randn({n, 45});
    h.trans = at::randn({n, 3});
    h.shape = at::randn({10});
  }
  if (vertices) s.hands.vertices = at::randn({2, n, 778, 3});
  return s;
}

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("bimart_io_tests_" + std::to_string(::getpid())) / name;
  fs::remove_all(p.parent_path() / name);
  return p;
}

TEST(Sequence, RoundTripKeepsEveryField) {
  for (bool with_vertices : {false, true}) {
    const Sequence s = make_sequence(5, with_vertices);
    const fs::path file = scratch("seqs") / "sub" / "a.npz";  // missing folders are created
    write_sequence(s, file.string());
    const Sequence r = read_sequence(file.string());
    EXPECT_EQ(r.name, s.name);
    EXPECT_EQ(r.object, s.object);
    EXPECT_EQ(r.category, s.category);
    EXPECT_EQ(r.kind, s.kind);
    EXPECT_EQ(r.fps, 30.0);
    EXPECT_EQ(r.num_frames(), 5);
    EXPECT_TRUE(at::equal(r.object_states, s.object_states));
    for (int h = 0; h < 2; ++h) {
      EXPECT_TRUE(at::equal(r.hands.hands[h].rot, s.hands.hands[h].rot));
      EXPECT_TRUE(at::equal(r.hands.hands[h].pose, s.hands.hands[h].pose));
      EXPECT_TRUE(at::equal(r.hands.hands[h].trans, s.hands.hands[h].trans));
      EXPECT_TRUE(at::equal(r.hands.hands[h].shape, s.hands.hands[h].shape));
    }
    EXPECT_EQ(r.hands.has_vertices(), with_vertices);
    if (with_vertices) EXPECT_TRUE(at::equal(r.hands.vertices, s.hands.vertices));
    // numpy-compatible keys
    const NpzFile npz = NpzFile::read(file.string());
    EXPECT_TRUE(npz.contains("left_rot") && npz.contains("right_shape") && npz.contains("object_states"));
  }
}

TEST(Sequence, DoublesAreStoredAsFloat32) {
  Sequence s = make_sequence(3, false);
  s.object_states = s.object_states.to(at::kDouble);
  const fs::path file = scratch("dbl") / "b.npz";
  write_sequence(s, file.string());
  const Sequence r = read_sequence(file.string());
  EXPECT_EQ(r.object_states.scalar_type(), at::kFloat);
  EXPECT_TRUE(at::allclose(r.object_states.to(at::kDouble), s.object_states));
}

TEST(Sequence, ValidationNamesTheField) {
  auto expect_error = [](const Sequence& s, const std::string& needle) {
    try {
      s.validate();
      ADD_FAILURE() << "no error for " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  Sequence s = make_sequence(4, false);
  EXPECT_NO_THROW(s.validate());
  Sequence a = s;
  a.hands.hands[1].pose = at::zeros({3, 45});
  expect_error(a, "right_pose");
  Sequence b = s;
  b.object_states = at::zeros({4, 6});
  expect_error(b, "object_states");
  Sequence c = s;
  c.hands.hands[0].trans = s.hands.hands[0].trans.clone();
  c.hands.hands[0].trans[2][1] = NAN;
  expect_error(c, "left_trans");
  Sequence d = s;
  d.fps = 0;
  expect_error(d, "fps");
  Sequence e = s;
  e.hands.vertices = at::zeros({2, 5, 778, 3});
  expect_error(e, "hand_vertices");
  Sequence f = s;
  f.object = "";
  expect_error(f, "object");
}

TEST(Sequence, FailedWriteLeavesNoFileAndBadFilesNameTheKey) {
  Sequence s = make_sequence(4, false);
  s.hands.hands[0].shape = at::zeros({9});
  const fs::path file = scratch("bad") / "c.npz";
  EXPECT_THROW(write_sequence(s, file.string()), Error);
  EXPECT_FALSE(fs::exists(file));
  // A file without the hands.
  NpzFile npz;
  npz.set("object", make_npy_strings({"x"}, {}));
  npz.set("fps", make_npy_scalar<double>(30));
  npz.set("object_states", make_npy(std::vector<float>(14, 0.f), {2, 7}));
  npz.write(file.string());
  try {
    read_sequence(file.string());
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("left_rot"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("c.npz"), std::string::npos) << e.what();
  }
}

TEST(Sequence, ObjectPathIsRelativeToTheSequenceFile) {
  Sequence s;
  s.object = "../objects/box_1";
  EXPECT_EQ(resolve_object_path(s, "/data/set/seqs/a.npz"), "/data/set/objects/box_1");
  s.object = "/abs/obj.yaml";
  EXPECT_EQ(resolve_object_path(s, "/data/set/seqs/a.npz"), "/abs/obj.yaml");
  s.object = "box.yaml";
  EXPECT_EQ(resolve_object_path(s, "seqs/a.npz"), "seqs/box.yaml");
}

}  // namespace
}  // namespace bimart
