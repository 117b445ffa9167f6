#include "core/synth/motion_table.h"

#include <cmath>

namespace bimart {
namespace {

constexpr double kDeg = M_PI / 180.0;

std::vector<CategoryMotion> make_table() {
  const Eigen::Vector3d up_y(0, 1, 0), up_z(0, 0, 1), front_x(-1, 0, 0), front_y(0, 1, 0);
  // category, up, front, lift, carry, turn, tilt, open, close, grab angle,
  // P(use in air), P(use with root motion), P(use starts open), stand height
  return {
      {"box", up_y, front_x, {0.08, 0.25}, {0.05, 0.35}, {0, 90 * kDeg}, {0, 25 * kDeg}, {0.5, 1.0}, {0, 0.3}, {0, 0}, 0.2, 0.3, 0.2, 0},
      {"laptop", up_y, front_x, {0.05, 0.20}, {0.05, 0.30}, {0, 60 * kDeg}, {0, 15 * kDeg}, {0.6, 0.95}, {0, 0.3}, {0, 0.7}, 0.1, 0.3, 0.3, 0.05},
      {"notebook", up_y, front_x, {0.08, 0.25}, {0.05, 0.30}, {0, 90 * kDeg}, {0, 30 * kDeg}, {0.4, 0.9}, {0, 0.3}, {0, 0}, 0.3, 0.3, 0.2, 0},
      {"microwave", up_z, front_y, {0.03, 0.10}, {0.0, 0.15}, {0, 30 * kDeg}, {0, 5 * kDeg}, {0.5, 1.0}, {0, 0.3}, {0, 0}, 0.0, 0.1, 0.2, 0},
      {"waffleiron", up_y, front_x, {0.05, 0.15}, {0.05, 0.25}, {0, 60 * kDeg}, {0, 10 * kDeg}, {0.5, 1.0}, {0, 0.3}, {0, 0}, 0.0, 0.2, 0.2, 0},
      {"capsulemachine", up_y, front_x, {0.04, 0.15}, {0.05, 0.25}, {0, 60 * kDeg}, {0, 10 * kDeg}, {0.6, 1.0}, {0, 0.3}, {0, 0}, 0.0, 0.2, 0.2, 0},
      {"espressomachine", up_y, front_x, {0.04, 0.12}, {0.05, 0.20}, {0, 45 * kDeg}, {0, 8 * kDeg}, {0.6, 1.0}, {0, 0.3}, {0, 0}, 0.0, 0.2, 0.2, 0},
      {"mixer", up_y, front_x, {0.04, 0.12}, {0.05, 0.20}, {0, 45 * kDeg}, {0, 8 * kDeg}, {0.6, 1.0}, {0, 0.3}, {0, 0}, 0.0, 0.2, 0.2, 0},
      {"ketchup", up_y, front_x, {0.10, 0.30}, {0.05, 0.35}, {0, 120 * kDeg}, {0, 60 * kDeg}, {0.5, 1.0}, {0, 0.3}, {0, 0}, 0.5, 0.2, 0.1, 0},
      {"phone", up_y, front_x, {0.10, 0.30}, {0.05, 0.30}, {0, 120 * kDeg}, {0, 45 * kDeg}, {0.5, 1.0}, {0, 0.3}, {0, 1.0}, 0.6, 0.2, 0.2, 0.05},
      {"scissors", up_z, front_x, {0.08, 0.25}, {0.05, 0.30}, {0, 90 * kDeg}, {0, 30 * kDeg}, {0.5, 1.0}, {0, 0.3}, {0, 0.5}, 0.6, 0.2, 0.1, 0.05},
  };
}

}  // namespace

const std::vector<CategoryMotion>& category_motions() {
  static const std::vector<CategoryMotion> table = make_table();
  return table;
}

const CategoryMotion& category_motion(const std::string& category) {
  for (const auto& row : category_motions())
    if (row.category == category) return row;
  static const CategoryMotion generic{"", Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(-1, 0, 0),
                                      {0.05, 0.20}, {0.05, 0.30}, {0, 60 * kDeg}, {0, 15 * kDeg},
                                      {0.5, 1.0}, {0, 0.3}, {0, 0}, 0.2, 0.3, 0.2, 0};
  return generic;
}

}  // namespace bimart
