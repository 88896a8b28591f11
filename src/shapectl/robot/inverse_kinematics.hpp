#pragma once
// Inverse kinematics: joints θ that put tool points at goal positions (and optionally tool
// frames at goal orientations), within joint limits and clear of self-collision.
// Damped least squares (Levenberg–Marquardt) on
//   ½ Σ_goals |p(θ) − p*|² + ½ w_R² |R(θ) − R*|²_F + collision_weight · (sphere barrier),
// or, for an axis goal, ½ w_R² |R(θ) a − a*|² in place of the rotation term,
// every step clamped to the joint limits moved inwards by `joint_limit_margin`. Deterministic:
// restarts from seeded random joints (std::mt19937) when the start does not converge.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

struct IkGoal {
  int link = -1;                       // the tool's link
  Vec3 point_link = Vec3::Zero();      // tool point in the link frame, metres
  Vec3 position_world = Vec3::Zero();  // where the tool point should be, metres
  // Wanted orientation of the link frame (world), or none for a position-only goal.
  std::optional<Eigen::Matrix3d> rotation_world = std::nullopt;
  // Or one axis only (a 5-DOF goal: free to turn about it): the unit link-frame axis
  // `axis_link` should point along the unit world direction `axis_world` (e.g. a gripper's
  // approach axis straight down). Ignored when rotation_world is set.
  std::optional<Vec3> axis_link = std::nullopt;
  Vec3 axis_world = Vec3::UnitZ();
  double orientation_weight = 0.1;  // metres per unit of |R − R*|_F: trades rotation for position
};

struct IkOptions {
  const CollisionModel* collisions = nullptr;  // may be null: no self-collision barrier
  double collision_weight = 1.0;
  double joint_limit_margin = 0.05;     // rad (m for prismatic); the result stays this far inside
  double position_tolerance = 1e-4;     // m, largest goal distance to accept
  double orientation_tolerance = 1e-3;  // rad, largest goal angle to accept
  int max_iterations = 300;             // per start
  int restarts = 8;                     // random starts after the first
  unsigned seed = 1;
  double max_step = 0.3;  // rad, largest joint change per iteration
};

enum class IkStatus { Converged, NotReached, Colliding, InvalidInput };
std::string_view to_string(IkStatus status);

struct IkResult {
  IkStatus status = IkStatus::InvalidInput;
  std::string reason;            // "goal 1 is 0.12 m away after 9 starts", ...
  Eigen::VectorXd joints;        // the best θ found (active joints); always within the limits
  double position_error = 0;     // m, largest over goals
  double orientation_error = 0;  // rad, largest over goals with an orientation or an axis
  double min_clearance = 0;      // m, +inf without collision model or pairs
  int iterations = 0;            // over all starts
  int starts = 0;                // starts tried (1 + restarts used)
};

// θ0 (size model.active_count()) is the first start; it is clamped into the limits.
IkResult solve_inverse_kinematics(const RobotModel& model, const std::vector<IkGoal>& goals,
                                  const Eigen::VectorXd& joints0, const IkOptions& options = {});

// The least-squares residuals at θ (½|r|² is the cost) and, if `jacobian` is not null, their
// derivative (rows × active_count). Exposed for derivative tests.
void ik_residuals(const RobotModel& model, const std::vector<IkGoal>& goals,
                  const IkOptions& options, const Eigen::VectorXd& joints,
                  Eigen::VectorXd& residuals, Eigen::MatrixXd* jacobian = nullptr);

}  // namespace shapectl
