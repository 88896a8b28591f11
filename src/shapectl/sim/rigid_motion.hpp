#pragma once
// The rigid part of a motion of the object's nodes. Elasticity is rotation-invariant, so the
// Hessian turns with the object: H(Rx) = R H(x) Rᵀ (3×3 blocks; grip springs are isotropic and
// gravity's Hessian is zero). A factorization made at x therefore serves at a rotated x once the
// rotation is undone, and a linear prediction x + u, which moves points along the tangent of a
// rotation and stretches the object by |ω|²r/2, is better with the rotation made finite.
#include <shapectl/types.hpp>

namespace shapectl {

// The rotation R minimizing Σᵢ |(toᵢ − c_to) − R (fromᵢ − c_from)|² (Kabsch; c the centroids).
Mat3 best_fit_rotation(const Positions& from, const Positions& to);

// Rᵀ applied to every node's 3-vector of v (R v with transpose = false).
Eigen::VectorXd rotate_nodes(const Mat3& R, const Eigen::VectorXd& v, bool transpose = false);

// x + u with u's best-fit infinitesimal rigid motion (v + ω × r about the centroid, least
// squares over the nodes) replaced by the finite one (v + (R(ω) − I) r), the rest of u turned
// by R(ω) with it. Equals x + u when u has no rotation.
Positions with_finite_rotation(const Positions& x, const Eigen::VectorXd& u);

}  // namespace shapectl
