#include "core/trajectory/cubic_spline.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <stdexcept>

namespace bimart {

CubicSpline::CubicSpline(std::vector<double> times, std::vector<double> values, End end, double start_slope,
                         double end_slope)
    : t_(std::move(times)), y_(std::move(values)) {
  if (t_.empty() || t_.size() != y_.size()) throw std::invalid_argument("CubicSpline: one value per time, at least one");
  const int n = static_cast<int>(t_.size());
  m_.assign(n, 0.0);
  if (n == 1) return;
  // The second derivatives M solve a symmetric positive definite tridiagonal system: the
  // first derivative is continuous at interior knots, plus one condition per end.
  std::vector<double> h(n - 1);
  for (int i = 0; i + 1 < n; ++i) h[i] = t_[i + 1] - t_[i];
  std::vector<Eigen::Triplet<double>> a;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  auto slope = [&](int i) { return (y_[i + 1] - y_[i]) / h[i]; };
  const bool natural = end == End::Natural;
  for (int i = 1; i + 1 < n; ++i) {
    // Natural ends fix M = 0 there, so their coupling terms vanish (which keeps A symmetric).
    if (!(natural && i - 1 == 0)) a.emplace_back(i, i - 1, h[i - 1]);
    a.emplace_back(i, i, 2 * (h[i - 1] + h[i]));
    if (!(natural && i + 1 == n - 1)) a.emplace_back(i, i + 1, h[i]);
    b[i] = 6 * (slope(i) - slope(i - 1));
  }
  if (natural) {
    a.emplace_back(0, 0, 1.0);
    a.emplace_back(n - 1, n - 1, 1.0);
  } else {
    a.emplace_back(0, 0, 2 * h[0]);
    a.emplace_back(0, 1, h[0]);
    b[0] = 6 * (slope(0) - start_slope);
    a.emplace_back(n - 1, n - 2, h[n - 2]);
    a.emplace_back(n - 1, n - 1, 2 * h[n - 2]);
    b[n - 1] = 6 * (end_slope - slope(n - 2));
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(a.begin(), a.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) throw std::runtime_error("CubicSpline: the spline system is singular");
  const Eigen::VectorXd m = solver.solve(b);
  for (int i = 0; i < n; ++i) m_[i] = m[i];
  slope_start_ = slope(0) - h[0] * (2 * m_[0] + m_[1]) / 6;
  slope_end_ = slope(n - 2) + h[n - 2] * (m_[n - 2] + 2 * m_[n - 1]) / 6;
}

double CubicSpline::operator()(double t) const {
  const std::size_t n = t_.size();
  if (n == 1) return y_[0];
  if (t <= t_.front()) return y_.front() + slope_start_ * (t - t_.front());
  if (t >= t_.back()) return y_.back() + slope_end_ * (t - t_.back());
  const std::size_t i = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin() - 1;
  const double h = t_[i + 1] - t_[i], a = (t_[i + 1] - t) / h, b = (t - t_[i]) / h;
  return a * y_[i] + b * y_[i + 1] + ((a * a * a - a) * m_[i] + (b * b * b - b) * m_[i + 1]) * h * h / 6;
}

double CubicSpline::derivative(double t) const {
  const std::size_t n = t_.size();
  if (n == 1) return 0;
  if (t <= t_.front()) return slope_start_;
  if (t >= t_.back()) return slope_end_;
  const std::size_t i = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin() - 1;
  const double h = t_[i + 1] - t_[i], a = (t_[i + 1] - t) / h, b = (t - t_[i]) / h;
  return (y_[i + 1] - y_[i]) / h + ((1 - 3 * a * a) * m_[i] + (3 * b * b - 1) * m_[i + 1]) * h / 6;
}

}  // namespace bimart
