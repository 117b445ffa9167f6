#include "joint_contact.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {

JointContact::JointContact(const ArticulatedObject& object, const at::Tensor& states_in, double reach) : reach_(reach) {
  if (!(reach >= 0)) throw Error("joint contact: 'contact_reach' must be >= 0 (metres), got " + std::to_string(reach));
  const at::Tensor states = states_in.to(at::kDouble).contiguous();
  if (states.dim() != 2 || states.size(1) != 7) throw Error("joint contact: object_states must be [N, 7]");
  const double* s = states.data_ptr<double>();
  for (std::int64_t t = 0; t < states.size(0); ++t) {
    const PosedObject posed = pose_canonical(object, s[7 * t]);
    Points3 all(posed.top.rows() + posed.bottom.rows(), 3);
    all << posed.top, posed.bottom;
    surfaces_.emplace_back(std::move(all));
  }
}

at::Tensor JointContact::impose(const at::Tensor& x0, std::int64_t first, int /*step*/, int /*num_steps*/) const {
  const std::int64_t B = x0.size(0), T = x0.size(1), D = x0.size(2);
  if (D % 3 != 0) throw Error("joint contact: need joints [B, T, 3k], got " + c10::str(x0.sizes()));
  if (first < 0 || first + T > static_cast<std::int64_t>(surfaces_.size()))
    throw Error("joint contact: frames [" + std::to_string(first) + ", " + std::to_string(first + T) + ") outside the " +
                std::to_string(surfaces_.size()) + " frames it was made for");
  at::Tensor out = x0.to(at::kFloat, false, true).contiguous();
  float* const p = out.data_ptr<float>();
  const double reach_sq = reach_ * reach_;
  at::parallel_for(0, B * T, 1, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t bt = begin; bt < end; ++bt) {
      const NearestPoints& surface = surfaces_[static_cast<std::size_t>(first + bt % T)];
      for (std::int64_t j = 0; j < D / 3; ++j) {
        float* q = p + bt * D + 3 * j;
        const NearestPoints::Hit h = surface.nearest(Eigen::Vector3d(q[0], q[1], q[2]));
        if (h.distance_sq >= reach_sq) continue;
        for (int c = 0; c < 3; ++c) q[c] = static_cast<float>(surface.points()(h.index, c));
      }
    }
  });
  return out.to(x0.scalar_type());
}

}  // namespace bimart
