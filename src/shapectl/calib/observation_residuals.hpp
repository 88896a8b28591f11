#pragma once
// The residuals of one observed frame against the model's equilibrium x̂, in units of the
// frame's σ, with their Jacobian through dx̂/dz:
//   marker at node i:  r = (x̂ᵢ − m) / σ                 (3 rows),  ∂r/∂z = (dx̂ᵢ/dz) / σ
//   cloud point p:     r = d(p, surface(x̂)) / σ         (1 row),   ∂r/∂z = −uᵀ Σₖ bₖ dx̂ₖ/dz / σ
// d is the distance to the closest point c = Σₖ bₖ x̂ₖ on the deformed surface triangles and
// u = (p − c)/d: the derivative of the distance through the closest point (its barycentrics
// bₖ held fixed, which is exact at a distance minimum).
// A depth camera's points move with its pose correction (calib/model_parameters.hpp): the
// residual is d(p', surface) with p' = CameraMotion p, and its camera columns
//   ∂r/∂δt = uᵀ / σ,   ∂r/∂δr = ((p' − o) × u)ᵀ / σ   (o the corrected camera's origin).
// Cloud points farther than the frame's cut-off τ are outliers (background, noise): they add
// the constant τ²/σ² to the cost and no row, a truncated quadratic that bounds their pull.
#include <vector>

#include <shapectl/calib/model_parameters.hpp>
#include <shapectl/calib/observations.hpp>
#include <shapectl/calib/surface_distance.hpp>

namespace shapectl {

struct FrameResiduals {
  Eigen::VectorXd residuals;  // markers first (3 each), then the inlier points
  Eigen::MatrixXd jacobian;   // rows as residuals, columns as dx̂/dz (empty without it)
  double outlier_cost = 0;    // ½ Σ τ²/σ² over the outliers
  int inlier_points = 0;
  double sum_squared_error = 0;  // Σ |x̂ᵢ − m|² + Σ d² over inliers, m²
  int observation_count = 0;     // markers + inlier points
  double cost() const { return 0.5 * residuals.squaredNorm() + outlier_cost; }
};

// A cut-off for the frame's cloud at the positions x: every point within 4σ, and otherwise
// points within 3 robust standard deviations (1.4826 × the median distance) of the surface,
// so a model still centimetres off keeps its inliers while background stays out; never beyond
// a quarter of the surface's bounding-box diagonal (a cloud mostly of background).
double outlier_cutoff(const ObservationFrame& frame, const SurfaceDistance& surface,
                      const CameraMotion& camera = {});

// `surface` must have been updated to x. dx_dz may be empty (residuals only). `camera` moves
// the frame's points (the identity for a frame without a depth image).
FrameResiduals frame_residuals(const ObservationFrame& frame, const Positions& x,
                               const SurfaceDistance& surface, double cutoff,
                               const Eigen::MatrixXd& dx_dz, const CameraMotion& camera = {});

}  // namespace shapectl
