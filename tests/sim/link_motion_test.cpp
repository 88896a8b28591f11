// LinkMotion's travel bound (link_motion.hpp) holds for points on every link of the two-arm
// robot along random straight joint paths, and is not far above the true travel.
#include <shapectl/sim/link_motion.hpp>

#include <gtest/gtest.h>

#include <random>

#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

TEST(LinkMotion, TravelBoundsTheMotionOfPointsOnTheLinks) {
  const Scene scene = test::two_arm_scene();
  const RobotModel& robot = *scene.robot->model;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  double tightest = 0;  // the largest true travel / bound seen
  for (int path = 0; path < 20; ++path) {
    Eigen::VectorXd from = scene.robot->reference_joints, to = from;
    for (int j = 0; j < from.size(); ++j) to[j] += 0.8 * u(rng);
    LinkMotion motion(robot, from, to);
    const KinematicsState start = motion.kinematics();
    for (int link = 0; link < robot.link_count(); ++link) {
      const Vec3 p_link(0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng));
      const auto world = [&](const KinematicsState& k) -> Vec3 {
        return k.T_world_link[link] * p_link;
      };
      for (double s : {0.0, 0.3, 0.7}) {
        motion.move_to(s);
        const Vec3 p = world(motion.kinematics());
        EXPECT_TRUE(motion.displacement(link).isApprox(motion.kinematics().T_world_link[link] *
                                                           start.T_world_link[link].inverse(),
                                                       1e-12));
        for (double h : {0.01, 0.1, 1 - s}) {
          double farthest = 0;  // sampled: the farthest the point gets from p within h
          for (int k = 1; k <= 50; ++k)
            farthest =
                std::max(farthest,
                         (world(forward_kinematics(robot, from + (s + k * h / 50) * (to - from))) -
                          p)
                             .norm());
          const double bound = motion.travel(link, p, h);
          EXPECT_LE(farthest, bound * (1 + 1e-12) + 1e-15) << "link " << link << " s " << s;
          if (!(bound > 0)) continue;  // a link no joint moves (the base)
          tightest = std::max(tightest, farthest / bound);
          // time_to_travel inverts travel.
          EXPECT_NEAR(motion.time_to_travel(link, p, bound), h, 1e-9);
        }
      }
    }
  }
  EXPECT_GT(tightest, 0.5);  // a bound, but not a loose one
}

}  // namespace
}  // namespace shapectl
