#include <shapectl/calib/joint_path.hpp>

#include <gtest/gtest.h>

#include <stdexcept>

#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

// A reading far off (a continuous joint's limits do not catch it) is refused before the first
// step, not walked for hours (issue 32: ~34 ms a radian).
TEST(JointPath, AWalkLongerThanTheStepLimitIsRefusedBeforeTheFirstStep) {
  const GrippedObject object(load_scene(test::source_path("scenes/yumi_bar.json")));
  Eigen::VectorXd far = object.reference_joints();
  far[2] += 1e6;
  try {
    equilibrium_along_path(object, far);
    FAIL() << "walked";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("rad from the reference joints, more than 1000 steps"),
              std::string::npos)
        << e.what();
  }
  far[2] = NAN;
  EXPECT_THROW(equilibrium_along_path(object, far), std::runtime_error);
  // A walk within the limit is taken.
  Eigen::VectorXd near = object.reference_joints();
  near[2] += 0.01;
  EXPECT_TRUE(equilibrium_along_path(object, near, 0.001).statics().converged());
}

}  // namespace
}  // namespace shapectl
