// The BPS basis: made once from a seed, stored, loaded (core/features/bps.h).
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/features/bps.h"
#include "core/io/npz.h"
#include "core/util/error.h"

namespace bimart {

namespace {

double unit_interval(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

BpsBasis make_bps_basis(int count, double radius, std::uint64_t seed) {
  if (count <= 0 || !(radius > 0)) throw Error("a BPS basis needs count > 0 and radius > 0");
  std::mt19937_64 rng(seed);
  BpsBasis b{Points3(count, 3), radius, seed};
  for (int i = 0; i < count;) {
    const Eigen::Vector3d p(2 * unit_interval(rng) - 1, 2 * unit_interval(rng) - 1, 2 * unit_interval(rng) - 1);
    if (p.squaredNorm() <= 1.0) b.points.row(i++) = radius * p.transpose();
  }
  return b;
}

BpsBasis load_bps_basis(const std::string& path) {
  const NpzFile f = NpzFile::read(path);
  BpsBasis b;
  const Eigen::MatrixXd pts = to_eigen(f.get("points", {-1, 3}), f.where("points"));
  b.points = pts;
  const std::vector<double> radius = f.vector<double>("radius");
  const std::vector<std::uint64_t> seed = f.vector<std::uint64_t>("seed");
  if (radius.size() != 1) throw Error(f.where("radius") + " must hold one number");
  if (seed.size() != 1) throw Error(f.where("seed") + " must hold one number");
  b.radius = radius[0];
  b.seed = seed[0];
  if (b.points.rows() == 0) throw Error(path + ": the BPS basis is empty");
  if (!(std::isfinite(b.radius) && b.radius > 0 && b.radius <= 10))
    throw Error(f.where("radius") + ": the ball radius must be in (0, 10] m, got " + std::to_string(b.radius));
  // Basis points lie in their ball (rounding aside); anything else is a damaged file.
  for (Eigen::Index i = 0; i < b.points.rows(); ++i)
    if (!(b.points.row(i).norm() <= 1.001 * b.radius))
      throw Error(f.where("points") + ": point " + std::to_string(i) + " lies outside the basis ball of radius " +
                  std::to_string(b.radius) + " m (or is not finite)");
  return b;
}

void save_bps_basis(const BpsBasis& basis, const std::string& path) {
  NpzFile f;
  f.set("points", make_npy(basis.points));
  f.set("radius", make_npy_scalar(basis.radius));
  f.set("seed", make_npy_scalar(basis.seed));
  f.write(path);
}

const char* default_basis_file(BpsVariant variant) {
  switch (variant) {
    case BpsVariant::Uniform: return "models/bps/u_bps_1024_r0.5.npz";
    case BpsVariant::PartAgnostic: return "models/bps/npa_bps_1024.npz";
    case BpsVariant::PerPart: return "models/bps/np_bps_512.npz";
  }
  return "";
}

int basis_size(BpsVariant variant) { return variant == BpsVariant::PerPart ? 512 : 1024; }

}  // namespace bimart
