// A hand model in MANO layout (DESIGN §4): template mesh, shape and pose-corrective blend
// shapes, joint regressor, skinning weights, kinematic tree, finger-pose PCA basis, and the
// fingertip and surface keypoint vertex ids. Stored as .npz (docs/formats.md, "Hand model").
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace bimart {

enum class HandSide { Left = 0, Right = 1 };

struct HandModel {
  HandSide side = HandSide::Right;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> v_template;  // [V,3] metres
  Eigen::MatrixXd shapedirs;         // [3V,10]: row 3*v+k = coordinate k of vertex v
  Eigen::MatrixXd posedirs;          // [3V,135]: pose-corrective blend shapes (15 joints x 9)
  Eigen::MatrixXd j_regressor;       // [16,V] dense
  Eigen::MatrixXd weights;           // [V,16] skinning weights, rows sum to 1
  std::array<int, 16> parents{};     // parents[0] = -1; MANO joint order (wrist; index1-3, middle1-3, pinky1-3, ring1-3, thumb1-3)
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> faces;  // [F,3]
  Eigen::MatrixXd hands_components;  // [45,45] finger-pose PCA basis, one component per row
  Eigen::VectorXd hands_mean;        // [45] mean finger pose
  std::array<int, 5> fingertips{};   // vertex ids: thumb, index, middle, ring, pinky
  std::vector<int> keypoints;        // J = 100 surface keypoint vertex ids (same for both sides)

  static constexpr int kNumJoints = 16;
  static constexpr int kNumBetas = 10;
  static constexpr int kNumPoseFeatures = 135;  // 15 joints x 9
  static constexpr int kPoseDim = 45;           // 15 joints x 3 (axis-angle)
  // Joint names in MANO order (glTF nodes, per-frame reports).
  static constexpr std::array<const char*, kNumJoints> kJointNames = {
      "wrist",  "index1", "index2", "index3", "middle1", "middle2", "middle3", "pinky1",
      "pinky2", "pinky3", "ring1",  "ring2",  "ring3",   "thumb1",  "thumb2",  "thumb3"};

  int num_vertices() const;
  int num_faces() const;
  // Consistent sizes, weights sum to 1, indices in range, tree valid; throws bimart::Error.
  void validate() const;
};

// The joint each vertex follows most (its largest skinning weight), MANO order.
int skinning_joint(const HandModel& m, int vertex);
// Each vertex's finger by that joint: 0 the palm (the wrist's), 1 index, 2 middle, 3 pinky,
// 4 ring, 5 thumb (MANO order).
std::vector<int> vertex_fingers(const HandModel& m);

// Reads and validates a hand model .npz; throws bimart::Error naming the file and key.
HandModel load_hand_model(const std::string& npz_path);
// Both hands, {left, right}: load_hand_model of each, and an error naming the file when a
// model is of the other side.
std::array<HandModel, 2> load_hand_models(const std::string& left_npz, const std::string& right_npz);
// Validates, then writes atomically (core/util/atomic_file.h).
void save_hand_model(const HandModel& model, const std::string& npz_path);

}  // namespace bimart
