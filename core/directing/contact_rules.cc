#include "core/directing/contact_rules.h"

#include <ATen/ATen.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bimart {
namespace {

// Rest positions (hinge at 0) of the hit vertices [N, 1024, 3], float64.
at::Tensor rest_hit_points(const ArticulatedObject& object, const at::Tensor& hits) {
  const auto rows = [](const TriangleMesh& m) {
    return at::from_blob(const_cast<double*>(m.vertices.data()), {static_cast<std::int64_t>(m.num_vertices()), 3},
                         at::kDouble);
  };
  const at::Tensor all = at::cat({rows(object.top), rows(object.bottom)}, 0);
  return all.index_select(0, hits.reshape({-1})).view({hits.size(0), hits.size(1), 3});
}

}  // namespace

ContactRules::ContactRules(const HandConstraints& constraints, const ArticulatedObject& object,
                           const at::Tensor& hit_indices) {
  const at::Tensor hits = hit_indices.to(at::kLong).contiguous();
  const std::int64_t N = hits.size(0), M = hits.size(1);
  floor_ = at::zeros({N, 2, M}, at::kFloat);
  required_ = at::zeros({N, 2, M}, at::kBool);
  touch_ = at::zeros({N, 2}, at::kBool);
  const at::Tensor top = hits < static_cast<std::int64_t>(object.top.num_vertices());  // [N, M]
  at::Tensor rest;
  for (const ContactConstraint& c : constraints.contacts) {
    if (c.frames.last >= N)
      throw Error(c.where, fmt::format("frames up to {}, but the trajectory has {} frames", c.frames.last, N));
    empty_ = false;
    const std::int64_t a = c.frames.first, b = c.frames.last + 1;
    at::Tensor floor = floor_.slice(0, a, b).select(1, c.hand);  // [T, M] views
    if (c.part == ContactPart::None) {
      floor.fill_(c.clearance);
      continue;
    }
    const at::Tensor t = top.slice(0, a, b);
    at::Tensor allowed = c.part == ContactPart::Top ? t : c.part == ContactPart::Bottom ? ~t : at::ones_like(t);
    at::Tensor forbidden = ~allowed;
    if (c.region) {
      if (!rest.defined()) rest = rest_hit_points(object, hits);
      const at::Tensor q = at::tensor({c.region->point.x(), c.region->point.y(), c.region->point.z()}, at::kDouble);
      const at::Tensor d = (rest.slice(0, a, b) - q).norm(2, -1);  // [T, M]
      forbidden = forbidden | (d > c.region->radius + kRegionReach);
      allowed = allowed & (d <= c.region->radius);
      if (!allowed.any(-1).all().item<bool>())
        throw Error(c.where, fmt::format("no point of the object's {} within {} m of ({}, {}, {}) (object frame, hinge "
                                         "at 0): move the region onto it or make it larger",
                                         c.part == ContactPart::Any ? "parts" : contact_part_name(c.part) + std::string(" part"),
                                         c.region->radius, c.region->point.x(), c.region->point.y(), c.region->point.z()));
    }
    floor.masked_fill_(forbidden, kOtherPartGap);
    required_.slice(0, a, b).select(1, c.hand).copy_(allowed);
    touch_.slice(0, a, b).select(1, c.hand).fill_(true);
  }
}

at::Tensor ContactRules::impose(const at::Tensor& maps, std::int64_t first, int /*step*/, int /*num_steps*/) const {
  if (empty_) return maps;
  const auto B = maps.size(0), T = maps.size(1);
  const std::int64_t M = floor_.size(2);
  if (first < 0 || first + T > floor_.size(0))
    throw Error(fmt::format("contact rules: frames [{}, {}) outside the {} frames they were made for", first, first + T,
                            floor_.size(0)));
  // One pass over each hand's row of M entries (a step's rules as tensor ops cost ~10 of them
  // over the whole window; this is one).
  const at::Tensor C = maps.to(at::kFloat, /*non_blocking=*/false, /*copy=*/true).reshape({B, T, 2, M}).contiguous();
  float* const c = C.data_ptr<float>();
  const float* const floor = floor_.data_ptr<float>();
  const bool* const required = required_.data_ptr<bool>();
  const bool* const touch = touch_.data_ptr<bool>();
  for (std::int64_t b = 0; b < B; ++b)
    for (std::int64_t t = 0; t < T; ++t)
      for (std::int64_t h = 0; h < 2; ++h) {
        const std::int64_t rule = (first + t) * 2 + h;
        float* const row = c + ((b * T + t) * 2 + h) * M;
        const float* const fl = floor + rule * M;
        const bool* const req = required + rule * M;
        float lowest = std::numeric_limits<float>::infinity();
        for (std::int64_t i = 0; i < M; ++i) {
          row[i] = std::max({row[i], 0.0f, fl[i]});
          if (req[i]) lowest = std::min(lowest, row[i]);
        }
        if (!touch[rule] || !std::isfinite(lowest)) continue;
        for (std::int64_t i = 0; i < M; ++i)
          if (req[i]) row[i] = std::max(row[i] - lowest, 0.0f);
      }
  return C.reshape(maps.sizes()).to(maps.scalar_type());
}

}  // namespace bimart
