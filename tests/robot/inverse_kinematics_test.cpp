// Inverse kinematics on the small two-arm robot: derivatives, reaching, limits, collisions.
#include <gtest/gtest.h>

#include <random>

#include <shapectl/robot/inverse_kinematics.hpp>

#include "support/derivative_check.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

RobotModel two_arms() {
  return RobotModel::from_urdf_string(test::two_arm_urdf(), "two_arms.urdf");
}

// Spheres along each forearm; with `tips` also one on each tool point.
CollisionModel arm_spheres(const RobotModel& model, double margin, bool tips = false) {
  std::vector<CollisionSphere> spheres;
  for (const char* link : {"l_link3", "r_link3"}) {
    for (double x : {0.05, 0.1, 0.15})
      spheres.push_back({model.link_index(link), Vec3(x, 0, 0), 0.03});
    if (tips) spheres.push_back({model.link_index(link), Vec3(0.2, 0, 0), 0.01});
  }
  return CollisionModel(model, spheres, margin, 1e6);
}

Eigen::VectorXd random_joints(const RobotModel& model, double inset, std::mt19937& rng) {
  const Eigen::VectorXd lo = model.lower_limits(), hi = model.upper_limits();
  Eigen::VectorXd q(model.active_count());
  for (int i = 0; i < q.size(); ++i)
    q[i] = std::uniform_real_distribution<double>(lo[i] + inset, hi[i] - inset)(rng);
  return q;
}

// Goals that FK at `q` meets exactly, for both tools; with `orientation` their frames too.
std::vector<IkGoal> goals_at(const RobotModel& model, const Eigen::VectorXd& q, bool orientation) {
  const KinematicsState s = forward_kinematics(model, q);
  std::vector<IkGoal> goals;
  for (const char* tool : {"l_tool", "r_tool"}) {
    const int link = model.link_index(tool);
    IkGoal g{.link = link,
             .point_link = Vec3(0.01, 0.02, 0),
             .position_world = s.T_world_link[link] * Vec3(0.01, 0.02, 0)};
    if (orientation) g.rotation_world = s.T_world_link[link].linear();
    goals.push_back(g);
  }
  return goals;
}

TEST(InverseKinematics, JacobianMatchesCentralDifferences) {
  const RobotModel model = two_arms();
  // A margin larger than the robot puts every sphere pair inside its barrier: those rows count too.
  const CollisionModel spheres = arm_spheres(model, 2.0);
  std::mt19937 rng(42);
  for (int trial = 0; trial < 5; ++trial) {
    auto goals = goals_at(model, random_joints(model, 0.1, rng), true);
    goals[0].position_world += Vec3(0.05, -0.02, 0.03);
    goals[1].rotation_world =
        Eigen::AngleAxisd(0.4, Vec3::UnitX()).toRotationMatrix() * *goals[1].rotation_world;
    const IkOptions options{.collisions = &spheres};
    const Eigen::VectorXd q = random_joints(model, 0.1, rng);
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    ik_residuals(model, goals, options, q, r, &J);
    ASSERT_EQ(J.rows(), 24 + spheres.pair_count());
    ASSERT_GT(J.bottomRows(spheres.pair_count()).cwiseAbs().maxCoeff(), 0)
        << "no collision row active";
    const auto residuals = [&](const Eigen::VectorXd& joints) -> Eigen::VectorXd {
      Eigen::VectorXd residual;
      ik_residuals(model, goals, options, joints, residual);
      return residual;
    };
    EXPECT_TRUE(test::derivative_matches(J, test::central_difference_jacobian(residuals, q, 1e-6),
                                         1e-6, "IK residual Jacobian"))
        << "trial " << trial;
  }
}

// Goals that FK at `q` meets, each tool's point and one axis of its frame (5-DOF goals).
std::vector<IkGoal> axis_goals_at(const RobotModel& model, const Eigen::VectorXd& q) {
  std::vector<IkGoal> goals = goals_at(model, q, false);
  const KinematicsState s = forward_kinematics(model, q);
  for (IkGoal& g : goals) {
    g.axis_link = Vec3(1, 2, -1).normalized();
    g.axis_world = s.T_world_link[g.link].linear() * *g.axis_link;
  }
  return goals;
}

TEST(InverseKinematics, AxisGoalJacobianMatchesCentralDifferences) {
  const RobotModel model = two_arms();
  std::mt19937 rng(43);
  for (int trial = 0; trial < 5; ++trial) {
    auto goals = axis_goals_at(model, random_joints(model, 0.1, rng));
    goals[1].axis_world = Eigen::AngleAxisd(0.5, Vec3::UnitY()) * goals[1].axis_world;
    const Eigen::VectorXd q = random_joints(model, 0.1, rng);
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    ik_residuals(model, goals, {}, q, r, &J);
    ASSERT_EQ(J.rows(), 12);
    const auto residuals = [&](const Eigen::VectorXd& joints) -> Eigen::VectorXd {
      Eigen::VectorXd residual;
      ik_residuals(model, goals, {}, joints, residual);
      return residual;
    };
    EXPECT_TRUE(test::derivative_matches(J, test::central_difference_jacobian(residuals, q, 1e-6),
                                         1e-6, "IK axis residual Jacobian"))
        << "trial " << trial;
  }
}

TEST(InverseKinematics, ReachesAxisGoalsTakenFromOtherJoints) {
  const RobotModel model = two_arms();
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const auto goals = axis_goals_at(model, random_joints(model, 0.2, rng));
    const IkResult result = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6));
    EXPECT_EQ(result.status, IkStatus::Converged) << result.reason;
    EXPECT_LE(result.orientation_error, 1e-3);
    const KinematicsState s = forward_kinematics(model, result.joints);
    for (const auto& g : goals)
      EXPECT_GT((s.T_world_link[g.link].linear() * *g.axis_link).dot(g.axis_world), std::cos(1e-3));
  }
  // A non-unit axis is invalid input, not a silent rescale.
  auto goals = axis_goals_at(model, Eigen::VectorXd::Zero(6));
  goals[0].axis_world *= 2;
  EXPECT_EQ(solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6)).status,
            IkStatus::InvalidInput);
}

TEST(InverseKinematics, ReachesPositionGoalsTakenFromOtherJoints) {
  const RobotModel model = two_arms();
  std::mt19937 rng(1);
  for (int trial = 0; trial < 5; ++trial) {
    const auto goals = goals_at(model, random_joints(model, 0.2, rng), false);
    const IkResult result = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6));
    EXPECT_EQ(result.status, IkStatus::Converged) << result.reason;
    EXPECT_LE(result.position_error, 1e-4);
    const KinematicsState s = forward_kinematics(model, result.joints);
    for (const auto& g : goals)
      EXPECT_LT((s.T_world_link[g.link] * g.point_link - g.position_world).norm(), 1e-4);
  }
}

TEST(InverseKinematics, ReachesPoseGoalsWithOrientation) {
  const RobotModel model = two_arms();
  std::mt19937 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    const auto goals = goals_at(model, random_joints(model, 0.2, rng), true);
    const IkResult result = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6));
    EXPECT_EQ(result.status, IkStatus::Converged) << result.reason;
    EXPECT_LE(result.orientation_error, 1e-3);
    const KinematicsState s = forward_kinematics(model, result.joints);
    for (const auto& g : goals)
      EXPECT_LT(Eigen::AngleAxisd(s.T_world_link[g.link].linear() * g.rotation_world->transpose())
                    .angle(),
                1e-3);
  }
}

TEST(InverseKinematics, GoalBeyondTheJointLimitsIsNotReachedAndJointsStayInside) {
  const RobotModel model = two_arms();
  // Joint 1 of each arm would have to turn by 2.8 rad; its limit is 2.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  q[0] = 2.8;
  q[3] = -2.8;
  const auto goals = goals_at(model, q, false);
  const IkOptions options{.joint_limit_margin = 0.05};
  const IkResult result = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6), options);
  EXPECT_EQ(result.status, IkStatus::NotReached);
  EXPECT_NE(result.reason.find("not reached"), std::string::npos) << result.reason;
  EXPECT_GT(result.position_error, 0.01);
  EXPECT_TRUE(((result.joints - model.lower_limits()).array() >= 0.05 - 1e-12).all())
      << result.joints.transpose();
  EXPECT_TRUE(((model.upper_limits() - result.joints).array() >= 0.05 - 1e-12).all())
      << result.joints.transpose();
}

TEST(InverseKinematics, GoalsBetweenTheArmsAreReachedClearOfCollision) {
  const RobotModel model = two_arms();
  const CollisionModel spheres = arm_spheres(model, 0.005);
  // Tools 8 cm apart in front of the robot: the arms must lean in without their spheres touching.
  std::vector<IkGoal> goals{{.link = model.link_index("l_tool"),
                             .position_world = Vec3(0.35, 0.04, 0.1)},
                            {.link = model.link_index("r_tool"),
                             .position_world = Vec3(0.35, -0.04, 0.1)}};
  const IkOptions options{.collisions = &spheres};
  const IkResult result = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6), options);
  EXPECT_EQ(result.status, IkStatus::Converged) << result.reason;
  EXPECT_GT(spheres.min_clearance(forward_kinematics(model, result.joints)), 0);
  EXPECT_GT(result.min_clearance, 0);
}

TEST(InverseKinematics, ToolsAtOnePointCannotBeReachedWithoutCollision) {
  const RobotModel model = two_arms();
  // Spheres on the tool points themselves: both at one point always overlap.
  const CollisionModel spheres = arm_spheres(model, 0.005, true);
  std::vector<IkGoal> goals{{.link = model.link_index("l_tool"),
                             .position_world = Vec3(0.35, 0, 0.1)},
                            {.link = model.link_index("r_tool"),
                             .position_world = Vec3(0.35, 0, 0.1)}};
  const IkOptions options{.collisions = &spheres, .restarts = 3};
  const IkResult result = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6), options);
  EXPECT_NE(result.status, IkStatus::Converged) << result.reason;
  EXPECT_EQ(result.starts, 4);
}

TEST(InverseKinematics, SameInputGivesTheSameJoints) {
  const RobotModel model = two_arms();
  std::mt19937 rng(4);
  const auto goals = goals_at(model, random_joints(model, 0.2, rng), false);
  const IkResult a = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6));
  const IkResult b = solve_inverse_kinematics(model, goals, Eigen::VectorXd::Zero(6));
  EXPECT_EQ(a.joints, b.joints);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(InverseKinematics, WrongStartSizeIsInvalidInput) {
  const RobotModel model = two_arms();
  const IkResult result = solve_inverse_kinematics(model, {}, Eigen::VectorXd::Zero(3));
  EXPECT_EQ(result.status, IkStatus::InvalidInput);
  EXPECT_NE(result.reason.find("expected 6"), std::string::npos) << result.reason;
  EXPECT_EQ(to_string(IkStatus::NotReached), "not_reached");
}

}  // namespace
}  // namespace shapectl
