#include "core/metrics/hand_vertices.h"

#include <array>
#include <memory>
#include <mutex>
#include <string>

#include <ATen/ATen.h>

#include <fmt/format.h>

#include <cmath>

#include "core/geometry/point_guard.h"
#include "core/hand/hand_model.h"
#include "core/hand/keypoints.h"
#include "core/hand/lbs_torch.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart {
namespace {

struct PosingHands {
  std::array<std::string, 2> files;
  std::shared_ptr<const std::array<HandModel, 2>> models;
  std::array<HandModelTensors, 2> tensors;
  std::array<std::vector<int64_t>, 2> keypoints;
};

std::shared_ptr<const PosingHands> load_posing_hands(const std::array<std::string, 2>& files) {
  auto hands = std::make_shared<PosingHands>();
  hands->files = files;
  hands->models = std::make_shared<const std::array<HandModel, 2>>(load_hand_models(files[0], files[1]));
  for (int h = 0; h < 2; ++h) {
    const HandModel& model = (*hands->models)[static_cast<size_t>(h)];
    hands->tensors[h] = HandModelTensors::from(model, at::kFloat);
    std::vector<int> ids;
    try {
      ids = model_keypoints(model);  // the same rule as every command
    } catch (const Error& e) {
      throw Error(files[static_cast<size_t>(h)] + ": " + e.message());
    }
    hands->keypoints[h].assign(ids.begin(), ids.end());
  }
  return hands;
}

// Posing refuses parameters beyond the documented bounds (core/geometry/point_guard.h):
// LBS of a rotation of 1e30 rad gives NaN vertices.
void check_pose_values(const at::Tensor& t, const std::string& field) {
  const at::Tensor d = t.detach().to(at::kCPU, at::kDouble).contiguous();
  const long bad = first_out_of_bounds(d.data_ptr<double>(), static_cast<long>(d.numel()), kMaxPoseValue);
  if (bad < 0) return;
  const int64_t per_frame = d.dim() >= 2 ? d.numel() / d.size(0) : d.numel();
  throw Error(fmt::format("field '{}'{}: value {:g} is {}", field,
                          d.dim() >= 2 ? fmt::format(", frame {} [{}]", bad / per_frame, bad % per_frame)
                                       : fmt::format(" [{}]", bad),
                          d.data_ptr<double>()[bad],
                          std::isfinite(d.data_ptr<double>()[bad]) ? fmt::format("beyond the bound ±{:g}", kMaxPoseValue)
                                                                   : std::string("not finite")));
}

std::mutex posing_mutex;
std::shared_ptr<const PosingHands> posing;  // null: the shipped models, loaded on first use

// The models in use, shared by every thread (read-only).
std::shared_ptr<const PosingHands> posing_hands() {
  std::lock_guard<std::mutex> lock(posing_mutex);
  if (!posing)
    posing = load_posing_hands({find_data_file("models/hand/mano_left.npz"), find_data_file("models/hand/mano_right.npz")});
  return posing;
}

}  // namespace

void set_posing_hand_models(const std::string& left_npz, const std::string& right_npz) {
  if (left_npz.empty() != right_npz.empty())
    throw Error("give both hand models (left and right) or neither");
  std::shared_ptr<const PosingHands> next =
      left_npz.empty() ? nullptr : load_posing_hands({left_npz, right_npz});  // load outside the lock
  std::lock_guard<std::mutex> lock(posing_mutex);
  posing = std::move(next);
}

std::array<std::string, 2> posing_hand_model_files() { return posing_hands()->files; }

at::Tensor hand_vertices(const HandMotion& motion) {
  const int64_t n = motion.num_frames();
  if (motion.has_vertices()) {
    const at::Tensor& v = motion.vertices;
    if (v.dim() != 4 || v.size(0) != 2 || v.size(1) != n || v.size(3) != 3)
      throw Error("hand vertices must be [2, N, V, 3] with N = " + std::to_string(n) + " frames");
    // The same hands as the model poses: keypoints and contact maps index into them.
    const std::shared_ptr<const PosingHands> models = posing_hands();
    const int64_t expected = models->tensors[0].v_template.size(0);
    if (v.size(2) != expected)
      throw Error("field 'hand_vertices' has " + std::to_string(v.size(2)) + " vertices per hand, but the hand model (" +
                  models->files[0] + ") has " + std::to_string(expected));
    return v.to(at::kCPU, at::kFloat).contiguous();
  }
  if (n < 1) throw Error("hand motion has no frames");
  const std::shared_ptr<const PosingHands> models = posing_hands();
  std::vector<at::Tensor> per_hand;
  at::NoGradGuard no_grad;
  for (int h = 0; h < 2; ++h) {
    const HandParams& p = motion.hands[static_cast<size_t>(h)];
    const std::string side = h == 0 ? "left_" : "right_";
    check_pose_values(p.rot, side + "rot");
    check_pose_values(p.pose, side + "pose");
    check_pose_values(p.trans, side + "trans");
    check_pose_values(p.shape, side + "shape");
    auto f = [](const at::Tensor& t) { return t.detach().to(at::kCPU, at::kFloat).contiguous(); };
    const at::Tensor betas = f(p.shape).reshape({1, -1}).expand({n, -1}).contiguous();
    per_hand.push_back(lbs(models->tensors[h], f(p.rot), f(p.pose), f(p.trans), betas).vertices);
  }
  return at::stack(per_hand).contiguous();
}

std::shared_ptr<const std::array<HandModel, 2>> posing_hand_models() { return posing_hands()->models; }

at::Tensor hand_keypoints(const HandMotion& motion) {
  const at::Tensor v = hand_vertices(motion);
  const std::shared_ptr<const PosingHands> models = posing_hands();
  std::vector<at::Tensor> per_hand;
  for (int h = 0; h < 2; ++h) {
    const auto& ids = models->keypoints[h];
    for (int64_t id : ids)
      if (id >= v.size(2))
        throw Error("hand vertices have " + std::to_string(v.size(2)) +
                    " vertices per hand; the hand model's keypoints need " + std::to_string(id + 1));
    const at::Tensor idx = at::tensor(ids, at::kLong);
    per_hand.push_back(v[h].index_select(1, idx));
  }
  return at::stack(per_hand).contiguous();
}

}  // namespace bimart
