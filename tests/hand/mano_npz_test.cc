// Reads a hand model written by tools/mano_to_npz.py. The ctest entry tools.mano_to_npz
// (tests/tools/test_mano_to_npz.py) runs this with the converted file and the values it
// expects, the latter saved by numpy, and reads back with numpy what this test saves; on
// its own this test is skipped.
#include <gtest/gtest.h>

#include <cstdlib>

#include "core/hand/hand_model.h"
#include "core/io/npz.h"

namespace bimart {
namespace {

TEST(ManoConvertedFile, LoadsWithTheValuesNumpyWrote) {
  const char* model_path = std::getenv("BIMART_TEST_MANO_NPZ");
  const char* expected_path = std::getenv("BIMART_TEST_MANO_EXPECTED");
  if (!model_path || !expected_path) GTEST_SKIP() << "run by tests/tools/test_mano_to_npz.py";

  const HandModel m = load_hand_model(model_path);
  const NpzFile e = NpzFile::read(expected_path);  // stored members, written by np.savez
  const int64_t V = e.get("v_template").shape[0];
  ASSERT_EQ(m.num_vertices(), V);
  EXPECT_EQ(m.v_template, e.matrix("v_template"));
  EXPECT_EQ(m.shapedirs, to_eigen(e.get("shapedirs"), 3 * V, 10));
  EXPECT_EQ(m.posedirs, to_eigen(e.get("posedirs"), 3 * V, 135));
  EXPECT_EQ(m.j_regressor, e.matrix("J_regressor_dense"));
  EXPECT_EQ(m.weights, e.matrix("weights"));
  EXPECT_EQ(m.hands_components, e.matrix("hands_components"));
  EXPECT_EQ(m.hands_mean, e.matrix("hands_mean"));
  const std::vector<int> parents = e.vector<int>("parents");
  EXPECT_EQ(std::vector<int>(m.parents.begin(), m.parents.end()), parents);
  EXPECT_EQ(m.faces.cast<double>(), e.matrix("f"));
  const std::vector<int> tips = e.vector<int>("fingertip_verts");
  EXPECT_EQ(std::vector<int>(m.fingertips.begin(), m.fingertips.end()), tips);
  EXPECT_EQ(m.side, e.vector<int>("is_right")[0] ? HandSide::Right : HandSide::Left);
  EXPECT_TRUE(m.keypoints.empty());

  // Saved again for the Python side to read with numpy.
  if (const char* resaved = std::getenv("BIMART_TEST_MANO_RESAVED")) save_hand_model(m, resaved);
}

}  // namespace
}  // namespace bimart
