#include <shapectl/contact/barrier.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace shapectl {

BarrierValue barrier(double d, double dhat) {
  if (!(d > 0)) {
    const double inf = std::numeric_limits<double>::infinity();
    return {inf, -inf, inf};
  }
  if (d >= dhat) return {};
  const double e = d - dhat, log_ratio = std::log(d / dhat);
  return {-e * e * log_ratio, -2 * e * log_ratio - e * e / d,
          -2 * log_ratio - 4 * e / d + e * e / (d * d)};
}

void check_barrier_parameters(const char* term, double distance, double stiffness) {
  if (!(distance > 0) || !std::isfinite(distance))
    throw std::invalid_argument(std::string(term) + ": distance must be positive and finite");
  if (!(stiffness >= 0) || !std::isfinite(stiffness))
    throw std::invalid_argument(std::string(term) + ": stiffness must be non-negative and finite");
}

}  // namespace shapectl
