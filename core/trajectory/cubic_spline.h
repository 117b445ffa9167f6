// An interpolating cubic spline of one value over strictly increasing times: C² inside the
// span of its knots. Ends either clamped (a given first derivative, e.g. 0 = at rest) or
// natural (zero second derivative). Outside the span it continues without a jump: held at
// the end value when clamped to zero velocity, otherwise linearly with the end slope (which
// keeps a natural spline C² there too).
#pragma once

#include <vector>

namespace bimart {

class CubicSpline {
 public:
  enum class End { Natural, Clamped };

  // `times` strictly increasing, one value each; a single knot gives a constant. Clamped
  // ends take the slopes `start_slope` and `end_slope`.
  CubicSpline(std::vector<double> times, std::vector<double> values, End end, double start_slope = 0.0,
              double end_slope = 0.0);

  double operator()(double t) const;
  double derivative(double t) const;

  double first_time() const { return t_.front(); }
  double last_time() const { return t_.back(); }

 private:
  std::vector<double> t_, y_;
  std::vector<double> m_;  // second derivatives at the knots
  double slope_start_ = 0, slope_end_ = 0;  // first derivatives at the two ends
};

}  // namespace bimart
