#include "core/hand/hand_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>

#include "core/io/npz.h"
#include "tests/hand/synthetic_model.h"
#include "tests/synth/shipped_hands.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class HandModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("bimart_hand_model_test_" + std::string(
                ::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

void expect_identical(const HandModel& a, const HandModel& b) {
  EXPECT_EQ(a.side, b.side);
  EXPECT_EQ(a.v_template, b.v_template);
  EXPECT_EQ(a.shapedirs, b.shapedirs);
  EXPECT_EQ(a.posedirs, b.posedirs);
  EXPECT_EQ(a.j_regressor, b.j_regressor);
  EXPECT_EQ(a.weights, b.weights);
  EXPECT_EQ(a.parents, b.parents);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.hands_components, b.hands_components);
  EXPECT_EQ(a.hands_mean, b.hands_mean);
  EXPECT_EQ(a.fingertips, b.fingertips);
  EXPECT_EQ(a.keypoints, b.keypoints);
}

TEST_F(HandModelTest, SaveThenLoadIsIdentical) {
  for (HandSide side : {HandSide::Left, HandSide::Right}) {
    const HandModel m = testing::make_synthetic_hand(50, 3, side);
    save_hand_model(m, path("hand.npz"));
    expect_identical(m, load_hand_model(path("hand.npz")));
  }
}

TEST_F(HandModelTest, WritesTheDocumentedKeysAndShapes) {
  const HandModel m = testing::make_synthetic_hand(30);
  save_hand_model(m, path("hand.npz"));
  const NpzFile npz = NpzFile::read(path("hand.npz"));
  EXPECT_EQ(npz.keys(), (std::vector<std::string>{
                            "J_regressor", "f", "fingertip_verts", "hands_components", "hands_mean",
                            "is_right", "keypoint_verts", "kintree_table", "posedirs", "shapedirs",
                            "v_template", "weights"}));
  EXPECT_EQ(npz.get("shapedirs").shape, (std::vector<int64_t>{30, 3, 10}));
  EXPECT_EQ(npz.get("posedirs").shape, (std::vector<int64_t>{30, 3, 135}));
  // shapedirs[v, k, l] is row 3v+k, column l.
  const std::vector<double> sd = npz.vector<double>("shapedirs");
  EXPECT_EQ(sd[(7 * 3 + 2) * 10 + 4], m.shapedirs(3 * 7 + 2, 4));
  const std::vector<int64_t> tree = npz.vector<int64_t>("kintree_table");
  EXPECT_EQ(tree[0], -1);
  EXPECT_EQ(tree[16 + 5], 5);
}

// Official MANO files: float32 arrays, uint32 faces, root parent stored as uint32 max,
// no bimart keys beyond is_right; 778 vertices give the MANO fingertip ids.
TEST_F(HandModelTest, LoadsOfficialLayoutConventions) {
  const HandModel m = testing::make_synthetic_hand(778, 5);
  NpzFile npz;
  npz.set("v_template", make_npy(m.v_template.cast<float>().eval()));
  npz.set("shapedirs", make_npy(m.shapedirs.cast<float>().eval(), {778, 3, 10}));
  npz.set("posedirs", make_npy(m.posedirs, {778, 3, 135}));
  npz.set("J_regressor", make_npy(m.j_regressor));
  npz.set("weights", make_npy(m.weights));
  Eigen::Matrix<uint32_t, 2, 16> tree;
  for (int j = 0; j < 16; ++j) tree.col(j) << (j == 0 ? 4294967295u : uint32_t(m.parents[j])), uint32_t(j);
  npz.set("kintree_table", make_npy(tree));
  npz.set("f", make_npy(m.faces.cast<uint32_t>().eval()));
  npz.set("hands_components", make_npy(m.hands_components));
  npz.set("hands_mean", make_npy(m.hands_mean, {45}));
  npz.set("is_right", make_npy_scalar(false));
  npz.write(path("official.npz"));

  const HandModel r = load_hand_model(path("official.npz"));
  EXPECT_EQ(r.side, HandSide::Left);
  EXPECT_EQ(r.parents, m.parents);
  EXPECT_EQ(r.faces, m.faces);
  EXPECT_EQ(r.v_template, m.v_template.cast<float>().cast<double>());
  EXPECT_EQ(r.shapedirs, m.shapedirs.cast<float>().cast<double>());
  EXPECT_EQ(r.fingertips, (std::array<int, 5>{744, 320, 443, 554, 671}));
  EXPECT_TRUE(r.keypoints.empty());
}

TEST_F(HandModelTest, MissingFingertipsOnANonManoMeshIsAnError) {
  const HandModel m = testing::make_synthetic_hand(40);
  save_hand_model(m, path("hand.npz"));
  NpzFile npz = NpzFile::read(path("hand.npz"));
  NpzFile without;
  for (const auto& k : npz.keys())
    if (k != "fingertip_verts") without.set(k, npz.get(k));
  without.write(path("nofingers.npz"));
  EXPECT_THAT(error_of([&] { load_hand_model(path("nofingers.npz")); }),
              HasSubstr(path("nofingers.npz") + ": array 'fingertip_verts' is missing"));

  NpzFile no_tree;
  for (const auto& k : npz.keys())
    if (k != "kintree_table") no_tree.set(k, npz.get(k));
  no_tree.write(path("notree.npz"));
  EXPECT_THAT(error_of([&] { load_hand_model(path("notree.npz")); }),
              HasSubstr(path("notree.npz") + ": no array 'kintree_table'"));

  NpzFile bad_shape = npz;
  bad_shape.set("weights", make_npy(Eigen::MatrixXd::Constant(40, 15, 1.0 / 15)));
  bad_shape.write(path("badshape.npz"));
  EXPECT_THAT(error_of([&] { load_hand_model(path("badshape.npz")); }),
              HasSubstr("array 'weights' has shape (40, 15), expected (40, 16)"));
}

TEST_F(HandModelTest, ValidateNamesWhatIsWrong) {
  const HandModel good = testing::make_synthetic_hand(20);
  EXPECT_NO_THROW(good.validate());
  EXPECT_EQ(good.num_vertices(), 20);
  EXPECT_EQ(good.num_faces(), 40);

  HandModel m = good;
  m.weights(3, 0) += 0.5;
  EXPECT_THAT(error_of([&] { m.validate(); }), HasSubstr("skinning weights of vertex 3 sum to"));
  m = good;
  m.parents[5] = 9;
  EXPECT_THAT(error_of([&] { m.validate(); }), HasSubstr("joint 5 has parent 9"));
  m = good;
  m.faces(2, 1) = 20;
  EXPECT_THAT(error_of([&] { m.validate(); }), HasSubstr("face indices must be in [0, 20), found 20"));
  m = good;
  m.shapedirs.resize(60, 9);
  EXPECT_THAT(error_of([&] { m.validate(); }), HasSubstr("shapedirs is 60 x 9, expected 60 x 10"));
  m = good;
  m.fingertips[4] = -1;
  EXPECT_THAT(error_of([&] { m.validate(); }), HasSubstr("fingertip vertex -1 out of range"));
  m = good;
  m.posedirs(0, 0) = std::nan("");
  EXPECT_THAT(error_of([&] { m.validate(); }), HasSubstr("posedirs has NaN"));
  // Saving refuses an invalid model and leaves no file.
  EXPECT_THAT(error_of([&] { save_hand_model(m, path("bad.npz")); }),
              HasSubstr("cannot save '" + path("bad.npz") + "'"));
  EXPECT_FALSE(fs::exists(path("bad.npz")));
}

// Each fingertip is on its own finger, and every finger and the palm has vertices: the
// refinement moves a finger's vertices together by these (pen_fingers_through).
TEST(VertexFingers, FingertipsAreOnTheirFingersAndEveryFingerHasVertices) {
  for (const HandModel* m : test::shipped_hands()) {
    const std::vector<int> f = vertex_fingers(*m);
    ASSERT_EQ(static_cast<int>(f.size()), m->num_vertices());
    // fingertips: thumb, index, middle, ring, pinky; fingers: 1 index, 2 middle, 3 pinky, 4 ring, 5 thumb
    const std::array<int, 5> expected = {5, 1, 2, 4, 3};
    for (int k = 0; k < 5; ++k) EXPECT_EQ(f[static_cast<size_t>(m->fingertips[static_cast<size_t>(k)])], expected[static_cast<size_t>(k)]);
    std::array<int, 6> count{};
    for (const int g : f) ++count[static_cast<size_t>(g)];
    for (int g = 0; g < 6; ++g) EXPECT_GT(count[static_cast<size_t>(g)], 20) << "finger " << g;
  }
}

}  // namespace
}  // namespace bimart
