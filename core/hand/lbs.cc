#include "core/hand/lbs.h"

#include <Eigen/Dense>

namespace bimart {

Eigen::VectorXd flat_pose_from_pca(const HandModel& m, const Eigen::VectorXd& coeffs) {
  const Eigen::Index n = coeffs.size();
  if (n > HandModel::kPoseDim)
    throw Error("flat_pose_from_pca: " + std::to_string(n) + " coefficients, at most 45");
  return m.hands_components.topRows(n).transpose() * coeffs + m.hands_mean;
}

Eigen::VectorXd pca_from_flat_pose(const HandModel& m, const Eigen::VectorXd& flat, int n) {
  if (n < 0 || n > HandModel::kPoseDim || flat.size() != HandModel::kPoseDim)
    throw Error("pca_from_flat_pose: need a 45-value pose and 0..45 components, got " +
                std::to_string(flat.size()) + " values and " + std::to_string(n));
  // min_c ||Cᵀ c − (flat − mean)|| over the first n rows C of hands_components.
  const Eigen::MatrixXd Ct = m.hands_components.topRows(n).transpose();
  return Ct.colPivHouseholderQr().solve(flat - m.hands_mean);
}

}  // namespace bimart
