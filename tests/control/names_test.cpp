// Every typed status and name: to_string and parse are inverse, names are unique, and the web
// client's shared list (web/js/protocol.js) carries every controller status the server sends.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>

#include <shapectl/control/controller.hpp>
#include <shapectl/control/optimize.hpp>

namespace shapectl {
namespace {

template <class E>
void expect_round_trip(std::initializer_list<E> values) {
  std::set<std::string> seen;
  for (E v : values) {
    const std::string name = to_string(v);
    EXPECT_NE(name, "?");
    EXPECT_TRUE(seen.insert(name).second) << "duplicate name " << name;
    E back{};
    ASSERT_TRUE(parse(name, &back)) << name;
    EXPECT_EQ(back, v) << name;
  }
  E unused{};
  EXPECT_FALSE(parse("no such name", &unused));
}

TEST(Names, EveryStatusAndKindRoundTrips) {
  expect_round_trip({ControllerStatus::Idle, ControllerStatus::Optimizing,
                     ControllerStatus::Reached, ControllerStatus::BestEffort,
                     ControllerStatus::Paused, ControllerStatus::Failed});
  expect_round_trip(
      {Shortfall::JointLimit, Shortfall::Collision, Shortfall::Reach, Shortfall::Buckling});
  expect_round_trip({Termination::Converged, Termination::IterationLimit, Termination::TimeLimit,
                     Termination::Stuck, Termination::Failed});
  expect_round_trip({OptimizerKind::GaussNewton, OptimizerKind::Lbfgs});
  expect_round_trip(
      {GradientMethod::Sensitivity, GradientMethod::Adjoint, GradientMethod::FiniteDifference});
  EXPECT_EQ(optimizer_names().size(), 2u);
  EXPECT_EQ(gradient_names().size(), 3u);
}

TEST(Names, TheWebClientKnowsEveryControllerStatus) {
  std::ifstream in(std::string(SHAPECTL_SOURCE_DIR) + "/web/js/protocol.js");
  ASSERT_TRUE(in) << "web/js/protocol.js missing";
  std::stringstream text;
  text << in.rdbuf();
  for (ControllerStatus s :
       {ControllerStatus::Idle, ControllerStatus::Optimizing, ControllerStatus::Reached,
        ControllerStatus::BestEffort, ControllerStatus::Paused, ControllerStatus::Failed})
    EXPECT_NE(text.str().find("'" + std::string(to_string(s)) + "'"), std::string::npos)
        << to_string(s) << " is not in web/js/protocol.js";
  for (Shortfall s :
       {Shortfall::JointLimit, Shortfall::Collision, Shortfall::Reach, Shortfall::Buckling})
    EXPECT_NE(text.str().find("'" + std::string(to_string(s)) + "'"), std::string::npos)
        << to_string(s) << " is not in web/js/protocol.js";
}

}  // namespace
}  // namespace shapectl
