#include "core/hand/hand_model.h"

#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "core/io/npz.h"
#include "core/util/error.h"

namespace bimart {
namespace {

constexpr int kJ = HandModel::kNumJoints;
// Official MANO files store the root's parent as uint32 max instead of -1.
constexpr int64_t kUint32Max = 4294967295LL;
// MANO right-hand fingertip vertex ids (thumb, index, middle, ring, pinky); the left
// model uses the same ids. Applied when a 778-vertex file has no fingertip_verts.
constexpr std::array<int, 5> kManoFingertips = {744, 320, 443, 554, 671};
constexpr int kManoVertices = 778;

std::string dims(Eigen::Index r, Eigen::Index c) {
  return std::to_string(r) + " x " + std::to_string(c);
}

void check_size(const char* name, Eigen::Index r, Eigen::Index c, Eigen::Index want_r,
                Eigen::Index want_c) {
  if (r != want_r || c != want_c)
    throw Error(std::string("hand model: ") + name + " is " + dims(r, c) + ", expected " +
                dims(want_r, want_c));
}

template <class M>
void check_finite(const char* name, const M& m) {
  if (!m.allFinite()) throw Error(std::string("hand model: ") + name + " has NaN or infinite values");
}

// A finite but absurd value (1e30 in a template) would make every posed vertex NaN or inf
// far downstream; the bounds are generous for any real hand model (MANO: template within
// 0.15 m, blend shapes under 0.05 m per unit, PCA components orthonormal).
template <class M>
void check_bounded(const char* name, const M& m, double bound, const char* unit) {
  Eigen::Index r = 0, c = 0;
  const double worst = m.cwiseAbs().maxCoeff(&r, &c);
  if (worst > bound)
    throw Error(fmt::format("hand model: {} has the value {:g} at [{}, {}], beyond the bound of {:g} {} for a hand model",
                            name, m(r, c), r, c, bound, unit));
}

}  // namespace

int skinning_joint(const HandModel& m, int vertex) {
  Eigen::Index j = 0;
  m.weights.row(vertex).maxCoeff(&j);
  return static_cast<int>(j);
}

std::vector<int> vertex_fingers(const HandModel& m) {
  std::vector<int> f(static_cast<size_t>(m.num_vertices()));
  for (int v = 0; v < m.num_vertices(); ++v) {
    const int j = skinning_joint(m, v);
    f[static_cast<size_t>(v)] = j == 0 ? 0 : (j - 1) / 3 + 1;
  }
  return f;
}

int HandModel::num_vertices() const { return static_cast<int>(v_template.rows()); }
int HandModel::num_faces() const { return static_cast<int>(faces.rows()); }

void HandModel::validate() const {
  const Eigen::Index V = v_template.rows();
  if (V == 0) throw Error("hand model: v_template has no vertices");
  check_size("shapedirs", shapedirs.rows(), shapedirs.cols(), 3 * V, kNumBetas);
  check_size("posedirs", posedirs.rows(), posedirs.cols(), 3 * V, kNumPoseFeatures);
  check_size("J_regressor", j_regressor.rows(), j_regressor.cols(), kJ, V);
  check_size("weights", weights.rows(), weights.cols(), V, kJ);
  check_size("hands_components", hands_components.rows(), hands_components.cols(), kPoseDim,
             kPoseDim);
  if (hands_mean.size() != kPoseDim)
    throw Error("hand model: hands_mean has " + std::to_string(hands_mean.size()) +
                " entries, expected 45");
  if (faces.rows() == 0) throw Error("hand model: no faces");
  check_finite("v_template", v_template);
  check_finite("shapedirs", shapedirs);
  check_finite("posedirs", posedirs);
  check_finite("J_regressor", j_regressor);
  check_finite("weights", weights);
  check_finite("hands_components", hands_components);
  check_finite("hands_mean", hands_mean);
  check_bounded("v_template", v_template, 2.0, "m");
  check_bounded("shapedirs", shapedirs, 1.0, "m per unit of shape");
  check_bounded("posedirs", posedirs, 1.0, "m per unit of pose feature");
  check_bounded("J_regressor", j_regressor, 10.0, "(regression weight)");
  check_bounded("hands_components", hands_components, 10.0, "rad");
  check_bounded("hands_mean", hands_mean, 2 * M_PI, "rad");

  for (Eigen::Index v = 0; v < V; ++v) {
    const double sum = weights.row(v).sum();
    if (std::abs(sum - 1.0) > 1e-4 || weights.row(v).minCoeff() < -1e-6)
      throw Error("hand model: skinning weights of vertex " + std::to_string(v) + " sum to " +
                  std::to_string(sum) + " (must be non-negative and sum to 1)");
  }
  if (parents[0] != -1)
    throw Error("hand model: the root joint's parent is " + std::to_string(parents[0]) +
                ", expected -1");
  for (int j = 1; j < kJ; ++j)
    if (parents[j] < 0 || parents[j] >= j)
      throw Error("hand model: joint " + std::to_string(j) + " has parent " +
                  std::to_string(parents[j]) + "; parents must come before their children");
  if (faces.minCoeff() < 0 || faces.maxCoeff() >= V)
    throw Error("hand model: face indices must be in [0, " + std::to_string(V) + "), found " +
                std::to_string(faces.minCoeff() < 0 ? faces.minCoeff() : faces.maxCoeff()));
  for (int i = 0; i < 5; ++i)
    if (fingertips[i] < 0 || fingertips[i] >= V)
      throw Error("hand model: fingertip vertex " + std::to_string(fingertips[i]) +
                  " out of range [0, " + std::to_string(V) + ")");
  for (int k : keypoints)
    if (k < 0 || k >= V)
      throw Error("hand model: keypoint vertex " + std::to_string(k) + " out of range [0, " +
                  std::to_string(V) + ")");
}

HandModel load_hand_model(const std::string& npz_path) {
  const NpzFile npz = NpzFile::read(npz_path);
  HandModel m;
  const NpyArray& vt = npz.get("v_template", {-1, 3});
  const int64_t V = vt.shape[0];
  m.v_template = to_eigen(vt, npz.where("v_template"));
  m.shapedirs = to_eigen(npz.get("shapedirs", {V, 3, HandModel::kNumBetas}), 3 * V,
                         HandModel::kNumBetas, npz.where("shapedirs"));
  m.posedirs = to_eigen(npz.get("posedirs", {V, 3, HandModel::kNumPoseFeatures}), 3 * V,
                        HandModel::kNumPoseFeatures, npz.where("posedirs"));
  m.j_regressor = to_eigen(npz.get("J_regressor", {kJ, V}), npz.where("J_regressor"));
  m.weights = to_eigen(npz.get("weights", {V, kJ}), npz.where("weights"));
  m.hands_components = to_eigen(npz.get("hands_components", {45, 45}), npz.where("hands_components"));
  m.hands_mean = to_eigen(npz.get("hands_mean", {45}), npz.where("hands_mean"));

  const std::vector<int64_t> tree =
      as_vector<int64_t>(npz.get("kintree_table", {2, kJ}), npz.where("kintree_table"));
  for (int j = 0; j < kJ; ++j) {
    const int64_t p = tree[j];
    if (j == 0 && (p == -1 || p == kUint32Max)) {
      m.parents[0] = -1;
    } else if (p < 0 || p >= kJ) {
      throw Error(npz.where("kintree_table") + ": joint " + std::to_string(j) + " has parent " +
                  std::to_string(p));
    } else {
      m.parents[j] = static_cast<int>(p);
    }
  }

  const NpyArray& f = npz.get("f", {-1, 3});
  const std::vector<int> fv = as_vector<int>(f, npz.where("f"));
  m.faces.resize(f.shape[0], 3);
  for (int64_t i = 0; i < f.shape[0] * 3; ++i) m.faces.data()[i] = fv[i];

  const NpyArray& right = npz.get("is_right", {});
  m.side = as_vector<int>(right, npz.where("is_right"))[0] != 0 ? HandSide::Right : HandSide::Left;

  if (npz.contains("fingertip_verts")) {
    const std::vector<int> tips =
        as_vector<int>(npz.get("fingertip_verts", {5}), npz.where("fingertip_verts"));
    std::copy(tips.begin(), tips.end(), m.fingertips.begin());
  } else if (V == kManoVertices) {
    m.fingertips = kManoFingertips;
  } else {
    throw Error(npz.where("fingertip_verts") + " is missing (required unless the model has " +
                std::to_string(kManoVertices) + " vertices, MANO's)");
  }
  if (npz.contains("keypoint_verts"))
    m.keypoints = as_vector<int>(npz.get("keypoint_verts", {-1}), npz.where("keypoint_verts"));

  try {
    m.validate();
  } catch (const Error& e) {
    throw Error(npz_path + ": " + e.message());
  }
  return m;
}

void save_hand_model(const HandModel& m, const std::string& npz_path) {
  try {
    m.validate();
  } catch (const Error& e) {
    throw Error("cannot save '" + npz_path + "': " + e.message());
  }
  const int64_t V = m.num_vertices();
  NpzFile npz;
  npz.set("v_template", make_npy(m.v_template));
  npz.set("shapedirs", make_npy(m.shapedirs, {V, 3, HandModel::kNumBetas}));
  npz.set("posedirs", make_npy(m.posedirs, {V, 3, HandModel::kNumPoseFeatures}));
  npz.set("J_regressor", make_npy(m.j_regressor));
  npz.set("weights", make_npy(m.weights));
  Eigen::Matrix<int64_t, 2, kJ> tree;
  for (int j = 0; j < kJ; ++j) {
    tree(0, j) = m.parents[j];
    tree(1, j) = j;
  }
  npz.set("kintree_table", make_npy(tree));
  npz.set("f", make_npy(Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>(m.faces)));
  npz.set("hands_components", make_npy(m.hands_components));
  npz.set("hands_mean", make_npy(m.hands_mean, {HandModel::kPoseDim}));
  npz.set("fingertip_verts", make_npy(std::vector<int32_t>(m.fingertips.begin(), m.fingertips.end())));
  if (!m.keypoints.empty())
    npz.set("keypoint_verts", make_npy(std::vector<int32_t>(m.keypoints.begin(), m.keypoints.end())));
  npz.set("is_right", make_npy_scalar(m.side == HandSide::Right));
  npz.write(npz_path, NpzCompression::Deflate);
}

std::array<HandModel, 2> load_hand_models(const std::string& left_npz, const std::string& right_npz) {
  std::array<HandModel, 2> m{load_hand_model(left_npz), load_hand_model(right_npz)};
  for (int h = 0; h < 2; ++h)
    if (m[static_cast<size_t>(h)].side != (h == 0 ? HandSide::Left : HandSide::Right))
      throw Error((h == 0 ? left_npz : right_npz) + ": is a " + (h == 0 ? "right" : "left") + " hand, expected a " +
                  (h == 0 ? "left" : "right") + " one");
  return m;
}

}  // namespace bimart
