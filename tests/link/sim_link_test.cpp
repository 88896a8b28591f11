// The default link: an in-process robot, made by the factory.
#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/link/make_robot_link.hpp>

#include "link/link_test_support.hpp"

namespace shapectl {
namespace {

using test::wait_until;

TEST(SimLink, FollowsTheTargetOnlyWhileArmedWithinTheLimits) {
  test::TempDir dir;
  const auto file = dir.path() / "sim.jsonl";
  const RobotModel robot = test::yumi_arms();
  {
    LinkConfig config;
    config.max_velocity = 1.5;
    config.max_acceleration = 6;
    auto link = make_robot_link(config, robot, {}, std::make_shared<SessionLog>(file));
    link->start();
    ASSERT_TRUE(wait_until([&] { return link->status().connected; }, 1));
    EXPECT_EQ(link->status().kind, "sim");
    const Eigen::VectorXd start = link->status().measured;
    Eigen::VectorXd target = (start.array() - 0.2).matrix();
    link->set_target(target, true);
    test::sleep_seconds(0.1);
    EXPECT_EQ(link->status().measured, start);
    ASSERT_TRUE(link->arm());
    ASSERT_TRUE(wait_until([&] { return link->status().arrived; }, 5));
    EXPECT_TRUE(wait_until([&] { return link->status().measured.isApprox(target, 1e-12); }, 1));

    link->set_target((target.array() + 0.1).matrix(), false);
    const LinkStatus s = link->status();
    EXPECT_FALSE(s.armed);
    EXPECT_EQ(s.reason, "optimizer marked the target unsafe (collision or limits)");
    link->stop();
  }
  const CommandLogCheck check = check_command_log(read_session_log(file), file.string());
  EXPECT_TRUE(check.ok()) << check.violations.front();
  EXPECT_GT(check.commands, 50);
}

TEST(LinkConfig, BadSettingsAreInputErrors) {
  const RobotModel robot = test::yumi_arms();
  LinkConfig c;
  c.max_velocity = -1;
  try {
    make_robot_link(c, robot);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "link: max_velocity: expected a positive number, got -1");
  }
  LinkKind kind;
  EXPECT_FALSE(parse("ros", &kind));
  for (LinkKind k : {LinkKind::Sim, LinkKind::Egm}) {
    ASSERT_TRUE(parse(to_string(k), &kind));
    EXPECT_EQ(kind, k);
  }
}

TEST(LinkConfig, VelocityIsNeverAboveTheRobotsOwn) {
  const RobotModel robot = test::yumi_arms();
  LinkConfig c;
  c.max_velocity = 100;
  const GovernorLimits g = governor_limits(c, robot);
  EXPECT_TRUE(g.velocity.isApprox(robot.velocity_limits()));
  EXPECT_TRUE(g.lower.isApprox((robot.lower_limits().array() + c.limit_margin).matrix()));
}

}  // namespace
}  // namespace shapectl
