#pragma once
// The motion of the obstacles on robot links along a path s ∈ [0, 1] (the joints moving from θ0
// to θ1), as the CCD of that motion (ObstacleContact::max_obstacle_step) needs it: where each
// link has moved, and a bound on how far a point on it can move. sim/link_motion.hpp makes one
// from the robot's kinematics.
#include <Eigen/Geometry>

#include <shapectl/types.hpp>

namespace shapectl {

class ObstacleMotion {
 public:
  virtual ~ObstacleMotion() = default;
  // Moves to s (forward kinematics there); s only grows.
  virtual void move_to(double s) = 0;
  // The rigid motion of `link` from s = 0 to the current s (world frame: T(s) T(0)⁻¹).
  virtual const Eigen::Isometry3d& displacement(int link) const = 0;
  // The largest h such that a point on `link`, at p (world) at the current s, moves by at most
  // `distance` over [s, s + h] (+inf if it does not move). A bound: it may be smaller.
  virtual double time_to_travel(int link, const Vec3& p, double distance) const = 0;
  // A bound on how far such a point moves over [s, s + h].
  virtual double travel(int link, const Vec3& p, double h) const = 0;
};

}  // namespace shapectl
