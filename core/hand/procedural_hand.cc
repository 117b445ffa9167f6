#include "core/hand/procedural_hand.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "core/hand/keypoints.h"
#include "core/hand/procedural_hand_mesh.h"
#include "core/util/error.h"
#include "core/util/random.h"

namespace bimart {

namespace {

// ---- Frame --------------------------------------------------------------------------------
// The hand is designed in a local frame (u along the fingers, w towards the thumb, n out of
// the back of the hand) and placed in MANO's right-hand frame: u = -x, w = +z, n = +y.
const Eigen::Vector3d kWristWorld(0.095, 0.006, 0.006);

Eigen::Matrix3d local_to_world() {
  Eigen::Matrix3d m;
  m.col(0) = Eigen::Vector3d(-1, 0, 0);
  m.col(1) = Eigen::Vector3d(0, 0, 1);
  m.col(2) = Eigen::Vector3d(0, 1, 0);
  return m;
}

Eigen::Vector3d to_world(const Eigen::Vector3d& local) { return kWristWorld + local_to_world() * local; }
Eigen::Vector3d to_local(const Eigen::Vector3d& world) { return local_to_world().transpose() * (world - kWristWorld); }

constexpr double kDeg = M_PI / 180.0;

// Unit direction at `yaw` degrees from u towards w, tilted `pitch` degrees towards n.
Eigen::Vector3d direction(double yaw, double pitch) {
  return {std::cos(pitch * kDeg) * std::cos(yaw * kDeg), std::cos(pitch * kDeg) * std::sin(yaw * kDeg),
          std::sin(pitch * kDeg)};
}

// ---- Rest skeleton --------------------------------------------------------------------------
// Digits in MANO chain order: index, middle, pinky, ring, thumb; digit c owns joints
// 1 + 3c .. 3 + 3c. Lengths are joint to joint, the last one to the centre of the tip's
// sphere; radii at the three joints and at the tip. Adult sizes (wrist to middle tip
// 18.6 cm, knuckle row 8.3 cm across) from hand anthropometry tables.
struct Digit {
  Eigen::Vector3d base;                // first joint (knuckle; for the thumb the CMC joint)
  std::array<Eigen::Vector3d, 3> dir;  // unit direction of each bone
  std::array<double, 3> len;
  std::array<double, 4> radius;
};

constexpr int kIndex = 0, kMiddle = 1, kPinky = 2, kRing = 3, kThumb = 4;

std::array<Digit, 5> rest_digits() {
  auto straight = [](Eigen::Vector3d base, double yaw, std::array<double, 3> len, std::array<double, 4> r) {
    const Eigen::Vector3d d = direction(yaw, 0);
    return Digit{base, {d, d, d}, len, r};
  };
  std::array<Digit, 5> d;
  d[kIndex] = straight({0.088, 0.028, 0}, 8, {0.040, 0.023, 0.016}, {0.0095, 0.0088, 0.0080, 0.0072});
  d[kMiddle] = straight({0.091, 0.006, 0}, 1, {0.044, 0.027, 0.017}, {0.0100, 0.0092, 0.0083, 0.0074});
  d[kPinky] = straight({0.077, -0.036, 0}, -14, {0.032, 0.019, 0.015}, {0.0083, 0.0076, 0.0070, 0.0063});
  d[kRing] = straight({0.085, -0.016, 0}, -6, {0.041, 0.026, 0.016}, {0.0093, 0.0086, 0.0078, 0.0070});
  // The thumb leaves the palm plane towards the palm side and bends towards the fingers.
  d[kThumb] = Digit{{0.022, 0.020, -0.010},
                    {direction(50, -15), direction(35, -10), direction(25, -5)},
                    {0.042, 0.031, 0.020},
                    {0.0135, 0.0110, 0.0095, 0.0082}};
  return d;
}

// ---- Shape ----------------------------------------------------------------------------------
struct ShapeFactors {
  double size = 1, palm_w = 1, palm_l = 1, palm_n = 1, knuckle = 0;
  std::array<double, 5> length{1, 1, 1, 1, 1};  // per digit
  double thickness = 1;
  std::array<double, 5> spread{0, 0, 0, 0, 0};  // radians about n, per digit
};

ShapeFactors shape_factors(const Eigen::VectorXd& b) {
  Eigen::VectorXd beta = Eigen::VectorXd::Zero(10);
  if (b.size() != 0) {
    if (b.size() != 10) throw Error("procedural hand: expected 10 shape values, got " + std::to_string(b.size()));
    beta = b;
  }
  ShapeFactors f;
  f.size = 1 + 0.10 * beta[0];
  f.palm_w = 1 + 0.10 * beta[1];
  f.palm_l = 1 + 0.10 * beta[2];
  for (int c : {kIndex, kMiddle, kPinky, kRing}) f.length[c] = 1 + 0.10 * beta[3];
  f.thickness = 1 + 0.12 * beta[4];
  f.length[kThumb] = 1 + 0.10 * beta[5];
  f.length[kIndex] *= 1 + 0.035 * beta[6];
  f.length[kRing] *= 1 - 0.035 * beta[6];
  f.palm_n = 1 + 0.15 * beta[7];
  f.spread = {4 * kDeg * beta[8], 0, -8 * kDeg * beta[8], -4 * kDeg * beta[8], 4 * kDeg * beta[8]};
  f.knuckle = 0.08 * beta[9];
  return f;
}

// Where the palm carries a rest point (local frame): stretched along and across, thickened,
// fanned out towards the knuckles, then scaled about the wrist.
Eigen::Vector3d palm_map(const ShapeFactors& f, const Eigen::Vector3d& p) {
  const double fan = 1 + f.knuckle * std::clamp(p.x() / 0.085, 0.0, 1.0);
  return f.size * Eigen::Vector3d(p.x() * f.palm_l, p.y() * f.palm_w * fan, p.z() * f.palm_n);
}

// The skeleton for a shape: joints, bone ends and radius scale, in the local frame.
struct Skeleton {
  std::array<Eigen::Vector3d, 16> joint;
  std::array<Eigen::Vector3d, 16> end;  // end of the bone each joint moves (joint 0: unused)
  std::array<Eigen::Vector3d, 5> tip;   // fingertip surface point per digit (chain order)
  double radius_scale = 1;
};

Skeleton skeleton(const ShapeFactors& f) {
  const auto digits = rest_digits();
  Skeleton s;
  s.joint[0] = Eigen::Vector3d::Zero();
  s.end[0] = Eigen::Vector3d::Zero();
  s.radius_scale = f.thickness * f.size;
  for (int c = 0; c < 5; ++c) {
    const Digit& d = digits[c];
    const Eigen::Matrix3d spread = Eigen::AngleAxisd(f.spread[c], Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::Vector3d p = palm_map(f, d.base);
    for (int k = 0; k < 3; ++k) {
      const int j = 1 + 3 * c + k;
      s.joint[j] = p;
      p += spread * d.dir[k] * d.len[k] * f.length[c] * f.size;
      s.end[j] = p;
    }
    s.tip[c] = p + spread * d.dir[2] * d.radius[3] * s.radius_scale;
  }
  return s;
}

// ---- Surface --------------------------------------------------------------------------------
// The hand is a smooth implicit surface: the palm is a rounded slab over a convex outline,
// each digit a chain of tapered capsules ("round cones"), the digits joined to the palm by
// a smooth minimum so that knuckles, webs and the thenar bulge blend in.
constexpr double kPalmRound = 0.0100;     // rounding radius of the palm slab
constexpr double kPalmHalf = 0.0030;      // half-thickness of its flat core
constexpr double kPalmCentreN = -0.0030;  // the palm's mid-plane sits a little palm-side
constexpr double kBlend = 0.008;          // smooth-minimum width, metres

// The palm core outline (u, w), counter-clockwise; the surface lies kPalmRound outside it.
const std::vector<Eigen::Vector2d>& palm_outline() {
  static const std::vector<Eigen::Vector2d> poly{{-0.010, -0.021}, {0.068, -0.031}, {0.080, -0.018},
                                                 {0.086, 0.004},   {0.082, 0.023},  {0.030, 0.026},
                                                 {-0.010, 0.018}};
  return poly;
}

// Signed distance to a simple polygon (negative inside): nearest edge plus a winding test.
double polygon_sdf(const std::vector<Eigen::Vector2d>& v, const Eigen::Vector2d& p) {
  double d2 = (p - v[0]).squaredNorm();
  double sign = 1;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i, ++i) {
    const Eigen::Vector2d e = v[j] - v[i], w = p - v[i];
    const Eigen::Vector2d b = w - e * std::clamp(w.dot(e) / e.dot(e), 0.0, 1.0);
    d2 = std::min(d2, b.squaredNorm());
    const bool c1 = p.y() >= v[i].y(), c2 = p.y() < v[j].y(), c3 = e.x() * w.y() > e.y() * w.x();
    if ((c1 && c2 && c3) || (!c1 && !c2 && !c3)) sign = -sign;
  }
  return sign * std::sqrt(d2);
}

double palm_sdf(const Eigen::Vector3d& p) {
  const double d2 = polygon_sdf(palm_outline(), Eigen::Vector2d(p.x(), p.y()));
  const Eigen::Vector2d q(d2, std::abs(p.z() - kPalmCentreN) - kPalmHalf);
  return std::min(std::max(q.x(), q.y()), 0.0) + q.cwiseMax(0.0).norm() - kPalmRound;
}

// Distance to a capsule whose radius goes linearly from r1 at a to r2 at b (the exact
// "round cone" distance, after Inigo Quilez's formula).
double round_cone_sdf(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r1,
                      double r2) {
  const Eigen::Vector3d ba = b - a, pa = p - a;
  const double l2 = ba.dot(ba), rr = r1 - r2, a2 = l2 - rr * rr, il2 = 1.0 / l2;
  const double y = pa.dot(ba), z = y - l2;
  const double x2 = (pa * l2 - ba * y).squaredNorm(), y2 = y * y * l2, z2 = z * z * l2;
  const double k = (rr > 0 ? 1 : rr < 0 ? -1 : 0) * rr * rr * x2;
  if ((z > 0 ? 1 : z < 0 ? -1 : 0) * a2 * z2 > k) return std::sqrt(x2 + z2) * il2 - r2;
  if ((y > 0 ? 1 : y < 0 ? -1 : 0) * a2 * y2 < k) return std::sqrt(x2 + y2) * il2 - r1;
  return (std::sqrt(x2 * a2 * il2) + y * rr) * il2 - r1;
}

double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

double hand_sdf(const Eigen::Vector3d& p) {
  static const auto digits = rest_digits();
  static const Skeleton s = skeleton(ShapeFactors{});
  double fingers = 1e9;
  for (int c = 0; c < 5; ++c)
    for (int k = 0; k < 3; ++k) {
      const int j = 1 + 3 * c + k;
      fingers = std::min(fingers, round_cone_sdf(p, s.joint[j], s.end[j], digits[c].radius[k], digits[c].radius[k + 1]));
    }
  return smooth_min(palm_sdf(p), fingers, kBlend);
}

// ---- Skinning weights -----------------------------------------------------------------------
// Bones as segments in the rest pose, each labelled with the joint that moves it: the
// metacarpals (wrist to each knuckle) belong to the wrist, the phalanges to their joints.
struct Bone {
  Eigen::Vector3d a, b;
  double ra, rb;
  int joint, digit;
};

std::vector<Bone> rest_bones() {
  const auto digits = rest_digits();
  const Skeleton s = skeleton(ShapeFactors{});
  std::vector<Bone> bones;
  for (int c = 0; c < 5; ++c) {
    bones.push_back({Eigen::Vector3d::Zero(), s.joint[1 + 3 * c], 0.012, 0.012, 0, c});
    for (int k = 0; k < 3; ++k) {
      const int j = 1 + 3 * c + k;
      bones.push_back({s.joint[j], s.end[j], digits[c].radius[k], digits[c].radius[k + 1], j, c});
    }
  }
  return bones;
}

// Distance from p to the bone's surface-less capsule, minus its radius there.
double bone_distance(const Bone& bone, const Eigen::Vector3d& p) {
  const Eigen::Vector3d e = bone.b - bone.a;
  const double t = std::clamp((p - bone.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (p - (bone.a + t * e)).norm() - (bone.ra + t * (bone.rb - bone.ra));
}

// Per vertex: the digit of the nearest bone, and weights over that digit's chain (wrist and
// its three joints) falling off exponentially with the extra distance to each joint's bone;
// then a few rounds of averaging over mesh neighbours, which blends across the webs.
// Hand-written: no Debian library computes skinning weights.
Eigen::MatrixXd skinning_weights(const Eigen::MatrixX3d& local, const TriangleMesh& mesh, std::vector<int>* digit_of) {
  constexpr double kFalloff = 0.0025;  // metres of extra distance per e-fold
  const auto bones = rest_bones();
  const Eigen::Index V = local.rows();
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(V, 16);
  digit_of->assign(V, 0);
  for (Eigen::Index v = 0; v < V; ++v) {
    const Eigen::Vector3d p = local.row(v).transpose();
    std::array<double, 16> d;
    d.fill(1e9);
    double best = 1e9;
    int digit = 0;
    for (const Bone& b : bones) {
      const double x = bone_distance(b, p);
      if (x < best) best = x, digit = b.digit;
    }
    for (const Bone& b : bones)
      if (b.digit == digit) d[b.joint] = std::min(d[b.joint], bone_distance(b, p));
    (*digit_of)[v] = digit;
    for (int j = 0; j < 16; ++j)
      if (d[j] < 1e8) W(v, j) = std::exp(-(d[j] - best) / kFalloff);
    W.row(v) /= W.row(v).sum();
  }
  std::vector<std::vector<int>> nb(V);
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) nb[mesh.faces(f, k)].push_back(mesh.faces(f, (k + 1) % 3)),
        nb[mesh.faces(f, (k + 1) % 3)].push_back(mesh.faces(f, k));
  for (int it = 0; it < 3; ++it) {
    Eigen::MatrixXd next = W;
    for (Eigen::Index v = 0; v < V; ++v) {
      Eigen::RowVectorXd avg = Eigen::RowVectorXd::Zero(16);
      for (int u : nb[v]) avg += W.row(u);
      next.row(v) = 0.5 * W.row(v) + 0.5 * avg / static_cast<double>(nb[v].size());
    }
    W = next;
  }
  for (Eigen::Index v = 0; v < V; ++v) {
    for (int j = 0; j < 16; ++j)
      if (W(v, j) < 1e-3) W(v, j) = 0;
    W.row(v) /= W.row(v).sum();
  }
  return W;
}

// ---- Joint regressor ------------------------------------------------------------------------
// Joint j = a weighted average of the vertices on a ring around it (near the plane through
// the joint across its bone, on its own digit). Gaussian weights in the distance to that
// plane are then changed as little as possible (least squares) so that the average is
// exactly the joint and the weights sum to 1.
Eigen::MatrixXd joint_regressor(const Eigen::MatrixX3d& local, const std::vector<int>& digit_of) {
  const auto digits = rest_digits();
  const Skeleton s = skeleton(ShapeFactors{});
  const Eigen::Index V = local.rows();
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(16, V);
  for (int j = 0; j < 16; ++j) {
    const Eigen::Vector3d J = s.joint[j];
    const int c = j == 0 ? -1 : (j - 1) / 3;
    const Eigen::Vector3d axis = j == 0 ? Eigen::Vector3d::UnitX() : (s.end[j] - J).normalized();
    const double max_perp = j == 0 ? 0.05 : 2.5 * digits[c].radius[(j - 1) % 3];
    std::vector<int> ids;
    std::vector<double> w0;
    for (double slab = 0.004; ids.size() < 8 && slab < 0.03; slab *= 1.5) {
      ids.clear();
      w0.clear();
      for (Eigen::Index v = 0; v < V; ++v) {
        if (c >= 0 && digit_of[v] != c) continue;
        const Eigen::Vector3d r = local.row(v).transpose() - J;
        const double along = r.dot(axis);
        if (std::abs(along) > slab || (r - along * axis).norm() > max_perp) continue;
        ids.push_back(static_cast<int>(v));
        w0.push_back(std::exp(-along * along / (slab * slab)));
      }
    }
    if (ids.size() < 4) throw Error("procedural hand: no vertex ring around joint " + std::to_string(j));
    const int n = static_cast<int>(ids.size());
    Eigen::MatrixXd A(4, n);
    Eigen::VectorXd w(n);
    for (int i = 0; i < n; ++i) {
      A.block<3, 1>(0, i) = local.row(ids[i]).transpose();
      A(3, i) = 1;
      w[i] = w0[i];
    }
    w /= w.sum();
    Eigen::Vector4d target;
    target << J, 1;
    w += A.transpose() * (A * A.transpose()).ldlt().solve(target - A * w);
    for (int i = 0; i < n; ++i) R(j, ids[i]) = w[i];
  }
  return R;
}

// ---- Shape directions -----------------------------------------------------------------------
// A shape moves every rest vertex by its skinning-weighted blend of per-bone maps: the palm
// map for the wrist, and for each phalanx the map that takes its rest bone onto the shaped
// bone (rotated, stretched along it by the length ratio, scaled across by the thickness).
Eigen::MatrixX3d shaped_vertices(const Eigen::MatrixX3d& local, const Eigen::MatrixXd& W, const Eigen::VectorXd& beta) {
  const ShapeFactors f = shape_factors(beta);
  const Skeleton rest = skeleton(ShapeFactors{}), shaped = skeleton(f);
  std::array<Eigen::Matrix3d, 16> M;
  for (int j = 1; j < 16; ++j) {
    const Eigen::Vector3d e0 = rest.end[j] - rest.joint[j], e1 = shaped.end[j] - shaped.joint[j];
    const Eigen::Vector3d a = e0.normalized();
    const double len = e1.norm() / e0.norm(), t = shaped.radius_scale;
    const Eigen::Matrix3d rot = Eigen::Quaterniond::FromTwoVectors(e0, e1).toRotationMatrix();
    M[j] = rot * (t * Eigen::Matrix3d::Identity() + (len - t) * a * a.transpose());
  }
  Eigen::MatrixX3d out(local.rows(), 3);
  for (Eigen::Index v = 0; v < local.rows(); ++v) {
    const Eigen::Vector3d p = local.row(v).transpose();
    Eigen::Vector3d q = W(v, 0) * palm_map(f, p);
    for (int j = 1; j < 16; ++j)
      if (W(v, j) > 0) q += W(v, j) * (shaped.joint[j] + M[j] * (p - rest.joint[j]));
    out.row(v) = q.transpose();
  }
  return out;
}

// ---- Finger poses ---------------------------------------------------------------------------
// Flexion axes in the rest pose: rotating a bone by +angle about `bone x m` turns it towards
// m (the palm, -n, for the fingers; the palm and the fingers for the thumb).
std::array<Eigen::Vector3d, 15> flexion_axes() {
  const auto digits = rest_digits();
  std::array<Eigen::Vector3d, 15> axes;
  const Eigen::Vector3d thumb_towards = Eigen::Vector3d(0, -0.6, -1).normalized();
  for (int c = 0; c < 5; ++c)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d m = c == kThumb ? thumb_towards : Eigen::Vector3d(0, 0, -1);
      axes[3 * c + k] = local_to_world() * digits[c].dir[k].cross(m).normalized();
    }
  return axes;
}

// Right-hand pose from per-digit curls and spreads (radians about the palm normal).
Eigen::VectorXd synergy_pose(const std::array<double, 5>& curl, const std::array<double, 5>& spread) {
  static const std::array<Eigen::Vector3d, 15> axes = flexion_axes();
  constexpr double kFinger[3] = {1.45, 1.70, 1.10};  // knuckle, middle and end joint at curl 1
  constexpr double kThumbFlex[3] = {0.55, 0.60, 0.90};
  const Eigen::Vector3d normal = local_to_world() * Eigen::Vector3d::UnitZ();
  Eigen::VectorXd pose = Eigen::VectorXd::Zero(45);
  for (int c = 0; c < 5; ++c)
    for (int k = 0; k < 3; ++k) {
      const double a = (c == kThumb ? kThumbFlex[k] : kFinger[k]) * curl[c];
      Eigen::Vector3d aa = a * axes[3 * c + k];
      if (k == 0) aa += spread[c] * normal;
      pose.segment<3>(3 * (3 * c + k)) = aa;
    }
  return pose;
}

// (a, b, c) -> (a, -b, -c) per joint: the mirror image x -> -x of a rotation.
Eigen::VectorXd mirror_pose(Eigen::VectorXd pose) {
  for (Eigen::Index i = 0; i < pose.size(); i += 3) pose[i + 1] = -pose[i + 1], pose[i + 2] = -pose[i + 2];
  return pose;
}

// PCA of sampled plausible finger poses: an overall curl (open hand to loose fist), each
// digit deviating from it, a little spread, and joint noise. Rows of the basis are unit
// principal directions, largest variance first, each with its largest entry positive.
void pose_pca(int samples, std::uint64_t seed, Eigen::MatrixXd* components, Eigen::VectorXd* mean) {
  Rng rng(seed);  // portable (core/util/random.h)
  constexpr std::array<double, 5> kSpreadSign{1.0, 0.2, -1.4, -0.8, 0.6};
  Eigen::MatrixXd X(samples, 45);
  for (int i = 0; i < samples; ++i) {
    const double overall = 0.9 * rng.uniform();
    std::array<double, 5> curl, spread;
    const double fan = 0.10 * rng.normal() * (1 - 0.6 * overall);
    for (int c = 0; c < 5; ++c) {
      curl[c] = std::clamp(overall + (c == kThumb ? 0.18 : 0.12) * rng.normal(), -0.05, 1.1);
      spread[c] = kSpreadSign[c] * fan + 0.03 * rng.normal();
    }
    Eigen::VectorXd pose = synergy_pose(curl, spread);
    for (int k = 0; k < 45; ++k) pose[k] += 0.03 * rng.normal();
    X.row(i) = pose.transpose();
  }
  *mean = X.colwise().mean().transpose();
  const Eigen::MatrixXd C = X.rowwise() - mean->transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C.transpose() * C / (samples - 1));
  components->resize(45, 45);
  for (int r = 0; r < 45; ++r) {
    Eigen::VectorXd v = eig.eigenvectors().col(44 - r);  // eigenvalues ascend
    Eigen::Index at;
    v.cwiseAbs().maxCoeff(&at);
    if (v[at] < 0) v = -v;
    components->row(r) = v.transpose();
  }
}

}  // namespace

const std::array<std::string, 10>& procedural_shape_names() {
  static const std::array<std::string, 10> names{"size",           "palm width",      "palm length",
                                                 "finger length",  "finger thickness", "thumb length",
                                                 "index/ring ratio", "palm thickness", "finger spread",
                                                 "knuckle width"};
  return names;
}

HandSkeleton procedural_hand_skeleton(HandSide side, const Eigen::VectorXd& betas) {
  const Skeleton s = skeleton(shape_factors(betas));
  HandSkeleton out;
  const double mirror = side == HandSide::Left ? -1 : 1;
  for (int j = 0; j < 16; ++j) out.joints[j] = to_world(s.joint[j]).cwiseProduct(Eigen::Vector3d(mirror, 1, 1));
  constexpr int kChainOfTip[5] = {kThumb, kIndex, kMiddle, kRing, kPinky};
  for (int t = 0; t < 5; ++t) out.tips[t] = to_world(s.tip[kChainOfTip[t]]).cwiseProduct(Eigen::Vector3d(mirror, 1, 1));
  return out;
}

Eigen::VectorXd procedural_curl_pose(HandSide side, double curl, double thumb_curl) {
  return procedural_digit_pose(side, {curl, curl, curl, curl, thumb_curl}, {0, 0, 0, 0, 0});
}

Eigen::VectorXd procedural_digit_pose(HandSide side, const std::array<double, 5>& curl,
                                      const std::array<double, 5>& spread) {
  const Eigen::VectorXd right = synergy_pose(curl, spread);
  return side == HandSide::Left ? mirror_pose(right) : right;
}

HandModel make_procedural_hand(HandSide side, const ProceduralHandOptions& options) {
  // Surface, meshed in MANO's right-hand frame.
  ImplicitMeshOptions mesh_options;
  mesh_options.target_vertices = options.target_vertices;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (int c = 0; c < 8; ++c) {  // the local box (u, w, n) around the hand, in world axes
    const Eigen::Vector3d corner(c & 1 ? 0.205 : -0.030, c & 2 ? 0.105 : -0.070, c & 4 ? 0.025 : -0.045);
    lo = lo.cwiseMin(to_world(corner));
    hi = hi.cwiseMax(to_world(corner));
  }
  const TriangleMesh mesh =
      mesh_implicit_surface([](const Eigen::Vector3d& p) { return hand_sdf(to_local(p)); }, lo, hi, mesh_options);
  const Eigen::Index V = mesh.num_vertices();
  Eigen::MatrixX3d local(V, 3);
  for (Eigen::Index v = 0; v < V; ++v) local.row(v) = to_local(mesh.vertices.row(v).transpose()).transpose();

  HandModel m;
  m.side = HandSide::Right;
  m.v_template = mesh.vertices;
  m.faces = mesh.faces;
  std::vector<int> digit_of;
  m.weights = skinning_weights(local, mesh, &digit_of);
  m.j_regressor = joint_regressor(local, digit_of);
  m.parents = {-1, 0, 1, 2, 0, 4, 5, 0, 7, 8, 0, 10, 11, 0, 13, 14};

  // Shape directions: central differences of the (nearly linear) shape map, in world axes.
  m.shapedirs.resize(3 * V, 10);
  const Eigen::Matrix3d L = local_to_world();
  for (int c = 0; c < 10; ++c) {
    Eigen::VectorXd beta = Eigen::VectorXd::Zero(10);
    beta[c] = 1;
    const Eigen::MatrixX3d plus = shaped_vertices(local, m.weights, beta);
    const Eigen::MatrixX3d minus = shaped_vertices(local, m.weights, -beta);
    for (Eigen::Index v = 0; v < V; ++v)
      m.shapedirs.block<3, 1>(3 * v, c) = L * (0.5 * (plus.row(v) - minus.row(v)).transpose());
  }
  m.posedirs = Eigen::MatrixXd::Zero(3 * V, HandModel::kNumPoseFeatures);
  pose_pca(options.pose_samples, options.seed, &m.hands_components, &m.hands_mean);

  // Fingertips: the vertex furthest out along each digit's last bone, near its axis.
  const Skeleton s = skeleton(ShapeFactors{});
  constexpr int kChainOfTip[5] = {kThumb, kIndex, kMiddle, kRing, kPinky};
  for (int t = 0; t < 5; ++t) {
    const int j = 3 + 3 * kChainOfTip[t];
    const Eigen::Vector3d a = (s.end[j] - s.joint[j]).normalized();
    double best = -1e9;
    for (Eigen::Index v = 0; v < V; ++v) {
      const Eigen::Vector3d r = local.row(v).transpose() - s.end[j];
      const double along = r.dot(a), score = along - 3 * (r - along * a).norm();
      if (score > best) best = score, m.fingertips[t] = static_cast<int>(v);
    }
  }
  m.keypoints = hand_keypoints(m, 100);

  if (side == HandSide::Left) {
    m.side = HandSide::Left;
    m.v_template.col(0) = -m.v_template.col(0);
    for (Eigen::Index v = 0; v < V; ++v) m.shapedirs.row(3 * v) = -m.shapedirs.row(3 * v);
    m.faces.col(1).swap(m.faces.col(2));
    for (int r = 0; r < 45; ++r) m.hands_components.row(r) = mirror_pose(m.hands_components.row(r).transpose()).transpose();
    m.hands_mean = mirror_pose(m.hands_mean);
  }
  m.validate();
  return m;
}

}  // namespace bimart
