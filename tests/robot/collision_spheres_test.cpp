#include <shapectl/robot/collision_spheres.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <shapectl/io/input_error.hpp>

#include "support/derivative_check.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const std::string kYumiDir = SHAPECTL_SOURCE_DIR "/data/robots/yumi/";

// base ─j1─ upper ─j2─ fore ─fixed─ hand ─j3─ finger; a second arm on j4.
const char* const kChainUrdf = R"(<robot name="chain">
  <link name="base"/><link name="upper"/><link name="fore"/><link name="hand"/><link name="finger"/>
  <link name="other"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="hand_joint" type="fixed"><parent link="fore"/><child link="hand"/>
    <origin xyz="0.3 0 0"/></joint>
  <joint name="j3" type="prismatic"><parent link="hand"/><child link="finger"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.1" velocity="1" effort="1"/></joint>
  <joint name="j4" type="revolute"><parent link="base"/><child link="other"/>
    <origin xyz="0 0.5 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
</robot>)";

int pairs_between(const RobotModel& robot, const CollisionModel& model, const char* a,
                  const char* b) {
  int count = 0;
  for (const auto& [i, j] : model.pairs()) {
    const std::string x =
        robot.links()[static_cast<std::size_t>(model.spheres()[static_cast<std::size_t>(i)].link)]
            .name;
    const std::string y =
        robot.links()[static_cast<std::size_t>(model.spheres()[static_cast<std::size_t>(j)].link)]
            .name;
    count += (x == a && y == b) || (x == b && y == a);
  }
  return count;
}

TEST(CollisionModel, SkipsAdjacentAndRigidlyJoinedLinksAndTheIgnoreList) {
  const RobotModel robot = RobotModel::from_urdf_string(kChainUrdf, "chain.urdf");
  std::vector<CollisionSphere> spheres;
  for (const char* link : {"base", "upper", "fore", "hand", "finger", "other"})
    spheres.push_back({robot.link_index(link), Vec3::Zero(), 0.05});
  const CollisionModel model(robot, spheres, 0.01, 1.0,
                             {{robot.link_index("other"), robot.link_index("fore")}});
  EXPECT_EQ(pairs_between(robot, model, "base", "upper"), 0);   // adjacent
  EXPECT_EQ(pairs_between(robot, model, "upper", "fore"), 0);   // adjacent
  EXPECT_EQ(pairs_between(robot, model, "upper", "hand"), 0);   // hand is rigid with fore
  EXPECT_EQ(pairs_between(robot, model, "fore", "hand"), 0);    // same rigid group
  EXPECT_EQ(pairs_between(robot, model, "fore", "finger"), 0);  // adjacent through the group
  EXPECT_EQ(pairs_between(robot, model, "other", "fore"), 0);   // ignored
  EXPECT_EQ(pairs_between(robot, model, "base", "fore"), 1);
  EXPECT_EQ(pairs_between(robot, model, "upper", "finger"), 1);
  EXPECT_EQ(pairs_between(robot, model, "other", "upper"), 1);
  EXPECT_EQ(pairs_between(robot, model, "other", "hand"), 1);
}

TEST(CollisionModel, ClearanceIsCentreDistanceMinusRadii) {
  const RobotModel robot = RobotModel::from_urdf_string(kChainUrdf, "chain.urdf");
  // A sphere on the hand (0.6 m out at j1 = j2 = 0) and one on `other` (0.5 m to the side).
  const CollisionModel model(robot,
                             {{robot.link_index("hand"), Vec3::Zero(), 0.1},
                              {robot.link_index("other"), Vec3::Zero(), 0.2}},
                             0.05, 2.0);
  const KinematicsState state = forward_kinematics(robot, Eigen::Vector4d::Zero());
  const double distance = std::sqrt(0.6 * 0.6 + 0.5 * 0.5);
  EXPECT_NEAR(model.min_clearance(state), distance - 0.3, 1e-12);
  EXPECT_EQ(model.value(robot, state), 0.0);
  // Swing the arm towards `other` until the spheres overlap by 0.1 (+ margin 0.05).
  const double reach = 0.6;
  const double angle = std::acos((reach * reach + 0.25 - 0.2 * 0.2) / (2 * reach * 0.5));
  const KinematicsState close =
      forward_kinematics(robot, Eigen::Vector4d(M_PI / 2 - angle, 0, 0, 0));
  EXPECT_NEAR(model.min_clearance(close), -0.1, 1e-9);
  EXPECT_NEAR(model.value(robot, close), 2.0 * std::pow(0.15, 3), 1e-12);
}

// Random YuMi configurations with some overlapping spheres, none within 1e-4 m of the kink at
// v = 0 (where central differences of v^{3/2} are inaccurate).
std::vector<Eigen::VectorXd> colliding_configurations(const RobotModel& robot,
                                                      const CollisionModel& model, int count) {
  std::mt19937 rng(42);
  std::vector<Eigen::VectorXd> out;
  while (static_cast<int>(out.size()) < count) {
    Eigen::VectorXd theta(robot.active_count());
    for (int i = 0; i < theta.size(); ++i)
      theta[i] = std::uniform_real_distribution<double>(robot.lower_limits()[i],
                                                        robot.upper_limits()[i])(rng);
    const KinematicsState state = forward_kinematics(robot, theta);
    bool near_kink = false;
    for (const auto& pair :
         model.closest_pairs(state, static_cast<std::size_t>(model.pair_count())))
      near_kink = near_kink || std::abs(pair.clearance + model.margin()) < 1e-4;
    if (!near_kink && model.value(robot, state) > 0) out.push_back(theta);
  }
  return out;
}

TEST(CollisionModel, BarrierGradientMatchesCentralDifferences) {
  const RobotModel robot = RobotModel::load_urdf_file(kYumiDir + "yumi.urdf");
  const CollisionModel model =
      CollisionModel::load_json_file(robot, kYumiDir + "yumi_spheres.json");
  const auto barrier = [&](const Eigen::VectorXd& t) {
    return model.value(robot, forward_kinematics(robot, t));
  };
  for (const Eigen::VectorXd& theta : colliding_configurations(robot, model, 5)) {
    Eigen::VectorXd gradient;
    model.value(robot, forward_kinematics(robot, theta), &gradient);
    EXPECT_TRUE(test::derivative_matches(gradient,
                                         test::central_difference_gradient(barrier, theta, 1e-6),
                                         1e-6, "collision barrier gradient"));
  }
}

TEST(CollisionModel, ResidualsSquareToTheBarrierAndTheirJacobianMatchesCentralDifferences) {
  const RobotModel robot = RobotModel::load_urdf_file(kYumiDir + "yumi.urdf");
  const CollisionModel model =
      CollisionModel::load_json_file(robot, kYumiDir + "yumi_spheres.json");
  const auto residuals = [&](const Eigen::VectorXd& t) -> Eigen::VectorXd {
    Eigen::VectorXd r;
    model.residuals(robot, forward_kinematics(robot, t), r);
    return r;
  };
  for (const Eigen::VectorXd& theta : colliding_configurations(robot, model, 3)) {
    const KinematicsState state = forward_kinematics(robot, theta);
    Eigen::VectorXd r;
    Eigen::MatrixXd jacobian;
    model.residuals(robot, state, r, &jacobian);
    ASSERT_EQ(r.size(), model.pair_count());
    EXPECT_NEAR(0.5 * r.squaredNorm(), model.value(robot, state), 1e-9 * model.value(robot, state));
    EXPECT_TRUE(test::derivative_matches(jacobian,
                                         test::central_difference_jacobian(residuals, theta, 1e-6),
                                         1e-6, "collision residual Jacobian"));
  }
}

TEST(CollisionModel, JsonNamesTheFileAndTheElement) {
  const RobotModel robot = RobotModel::from_urdf_string(kChainUrdf, "chain.urdf");
  const test::TempDir dir;
  const auto expect_error = [&](const std::string& text, const std::string& message) {
    const auto file = dir.write("spheres.json", text);
    try {
      CollisionModel::load_json_file(robot, file);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), file.string() + ": " + message);
    }
  };
  expect_error(R"({"spheres": {"elbow": []}})",
               "spheres.elbow: unknown link 'elbow' (not in chain.urdf)");
  expect_error(R"({"spheres": {"fore": [{"center": [0, 0, 0], "radius": -1}]}})",
               "spheres.fore[0].radius: expected a positive number, got -1");
  expect_error(R"({"spheres": {}, "ignore_pairs": [["fore", "wrist"]]})",
               "ignore_pairs[0][1]: unknown link 'wrist' (not in chain.urdf)");
  expect_error(
      R"({"spheres": {}, "margins": 1})",
      "margins: unknown key; known: description, margin, stiffness, spheres, ignore_pairs");
}

}  // namespace
}  // namespace shapectl
