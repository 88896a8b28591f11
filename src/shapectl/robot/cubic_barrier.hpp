#pragma once
// The one-sided C² barrier used for collisions and joint limits, on a violation v:
//   value    b(v) = k·v³ for v > 0, else 0      (b, b', b'' continuous at 0)
//   residual r(v) = sqrt(2k)·v^{3/2}           (½r² = b, for Gauss–Newton)
// v is in metres (collisions) or radians/metres (joint limits); k in objective units per v³.
#include <cmath>

namespace shapectl {

struct CubicBarrier {
  double stiffness = 1.0;  // k

  double value(double v) const { return v > 0 ? stiffness * v * v * v : 0.0; }
  double derivative(double v) const { return v > 0 ? 3 * stiffness * v * v : 0.0; }
  double residual(double v) const {
    return v > 0 ? std::sqrt(2 * stiffness) * v * std::sqrt(v) : 0.0;
  }
  double residual_derivative(double v) const {
    return v > 0 ? 1.5 * std::sqrt(2 * stiffness * v) : 0.0;
  }
};

}  // namespace shapectl
