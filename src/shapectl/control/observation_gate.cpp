#include <shapectl/control/observation_gate.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace shapectl {

double gate_radius(double variance, double sigma, const GateOptions& options) {
  const double q = options.model_error_allowance;
  const double s = std::min(sigma, q);
  return std::sqrt(options.chi_squared * (variance + q * q + s * s));
}

GateVerdict judge_innovations(const std::vector<Vec3>& innovations,
                              const std::vector<double>& variances, double sigma,
                              const GateOptions& options, GateCounts& counts) {
  GateVerdict v;
  int outside = 0;
  for (std::size_t k = 0; k < innovations.size(); ++k) {
    const Vec3& nu = innovations[k];
    const double radius = gate_radius(variances[k], sigma, options);
    v.radius = std::max(v.radius, radius);
    const double size = nu.allFinite() ? nu.norm() : std::numeric_limits<double>::infinity();
    v.inside.push_back(size <= radius);
    v.largest = std::max(v.largest, size);
    outside += !v.inside.back();
  }
  const int n = static_cast<int>(innovations.size());
  v.frame_rejected = 2 * outside > n;
  counts.markers_checked += n;
  counts.markers_rejected += outside;
  ++counts.frames_checked;
  counts.frames_rejected += v.frame_rejected;
  if (outside > 0) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "%d of %d markers outside the gate (largest innovation %.1f mm, gate %.1f mm)",
                  outside, n, v.largest * 1e3, v.radius * 1e3);
    v.reason = text;
  }
  return v;
}

}  // namespace shapectl
