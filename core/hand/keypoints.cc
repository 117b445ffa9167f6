#include "core/hand/keypoints.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include <Eigen/Geometry>

#include "core/util/error.h"

namespace bimart {

std::vector<int> hand_parts(const HandModel& model) {
  std::vector<int> part(model.weights.rows());
  for (Eigen::Index v = 0; v < model.weights.rows(); ++v) {
    Eigen::Index j;
    model.weights.row(v).maxCoeff(&j);
    part[v] = static_cast<int>(j);
  }
  return part;
}

std::vector<int> hand_keypoints(const HandModel& model, int J) {
  constexpr int kParts = HandModel::kNumJoints;
  const std::vector<int> part = hand_parts(model);
  const int V = static_cast<int>(model.v_template.rows());
  if (J > V) throw Error("hand_keypoints: " + std::to_string(J) + " keypoints from " + std::to_string(V) + " vertices");

  // Area per part: a third of each face's area to each of its vertices' parts.
  std::vector<double> area(kParts, 0.0);
  std::vector<std::vector<int>> members(kParts);
  for (int v = 0; v < V; ++v) members[part[v]].push_back(v);
  for (Eigen::Index f = 0; f < model.faces.rows(); ++f) {
    const Eigen::Vector3d a = model.v_template.row(model.faces(f, 0)), b = model.v_template.row(model.faces(f, 1)),
                          c = model.v_template.row(model.faces(f, 2));
    const double third = (b - a).cross(c - a).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[part[model.faces(f, k)]] += third;
  }

  // Counts: 2 each (or all vertices of a tiny part), the rest by largest remainder of area.
  std::vector<int> count(kParts, 0);
  int given = 0;
  double total_area = 0;
  for (int p = 0; p < kParts; ++p) {
    count[p] = std::min<int>(2, static_cast<int>(members[p].size()));
    given += count[p];
    total_area += area[p];
  }
  if (given > J) throw Error("hand_keypoints: " + std::to_string(J) + " keypoints cannot give every part 2");
  const int rest = J - given;
  std::vector<double> remainder(kParts, -1.0);
  int spent = 0;
  for (int p = 0; p < kParts; ++p) {
    const double share = total_area > 0 ? rest * area[p] / total_area : 0;
    const int extra = std::min(static_cast<int>(std::floor(share)), static_cast<int>(members[p].size()) - count[p]);
    count[p] += extra;
    spent += extra;
    if (count[p] < static_cast<int>(members[p].size())) remainder[p] = share - std::floor(share);
  }
  while (spent < rest) {  // hand out what is left, largest remainder first (then lowest part)
    int best = -1;
    for (int p = 0; p < kParts; ++p)
      if (count[p] < static_cast<int>(members[p].size()) && (best < 0 || remainder[p] > remainder[best])) best = p;
    if (best < 0) throw Error("hand_keypoints: not enough vertices");
    ++count[best];
    remainder[best] = -1.0;
    ++spent;
  }

  std::vector<int> out;
  out.reserve(J);
  for (int p = 0; p < kParts; ++p) {
    const std::vector<int>& ids = members[p];
    if (count[p] == 0) continue;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int v : ids) centroid += model.v_template.row(v).transpose();
    centroid /= static_cast<double>(ids.size());
    // dist[i]: distance from ids[i] to the nearest chosen vertex so far.
    std::vector<double> dist(ids.size(), std::numeric_limits<double>::infinity());
    std::size_t next = 0;
    for (std::size_t i = 0; i < ids.size(); ++i)
      if ((model.v_template.row(ids[i]).transpose() - centroid).norm() <
          (model.v_template.row(ids[next]).transpose() - centroid).norm())
        next = i;
    for (int k = 0; k < count[p]; ++k) {
      out.push_back(ids[next]);
      const Eigen::Vector3d chosen = model.v_template.row(ids[next]);
      std::size_t far = 0;
      for (std::size_t i = 0; i < ids.size(); ++i) {
        dist[i] = std::min(dist[i], (model.v_template.row(ids[i]).transpose() - chosen).norm());
        if (dist[i] > dist[far]) far = i;
      }
      next = far;
    }
  }
  return out;
}

std::vector<int> model_keypoints(const HandModel& model) {
  std::vector<int> ids = model.keypoints.empty() ? hand_keypoints(model, kNumKeypoints) : model.keypoints;
  if (static_cast<int>(ids.size()) != kNumKeypoints)
    throw Error("hand model has " + std::to_string(ids.size()) + " keypoints ('keypoint_verts'), expected " +
                std::to_string(kNumKeypoints));
  return ids;
}

}  // namespace bimart
