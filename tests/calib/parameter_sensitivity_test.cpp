#include <shapectl/calib/model_parameters.hpp>

#include <gtest/gtest.h>

#include "support/derivative_check.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

// The two-arm bar with a TCP off the link origin, grips already offset, a tight tolerance.
Scene offset_scene() {
  Scene scene = test::two_arm_scene({12, 2, 2});
  for (auto& ee : scene.robot->end_effectors) ee.tcp_link = Vec3(0.01, -0.004, 0.006);
  scene.grips[0].offset.translation() = Vec3(0.002, -0.001, 0.003);
  scene.grips[0].offset.linear() =
      Eigen::AngleAxisd(0.04, Vec3(1, 2, -1).normalized()).toRotationMatrix();
  scene.grips[1].offset.translation() = Vec3(-0.003, 0.002, 0.0);
  scene.statics.relative_tolerance = 1e-12;
  return scene;
}

Positions equilibrium(const Scene& scene, const Eigen::VectorXd& joints, const Positions& warm) {
  GrippedObject object(scene);
  ObjectState state = object.solve_from(joints, warm);
  EXPECT_TRUE(state.statics().converged()) << state.statics().reason;
  return state.positions();
}

TEST(ParameterSensitivity, EveryFittableParameterMatchesCentralDifferences) {
  const Scene scene = offset_scene();
  const FitSelection all{.youngs_modulus = true,
                         .poisson_ratio = true,
                         .density = true,
                         .grip_offsets = true};
  const ParameterSpace space(scene, all);
  ASSERT_EQ(space.size(), 3 + 12);
  const PhysicalParameters p = PhysicalParameters::of(scene);

  GrippedObject object(scene);
  Eigen::VectorXd joints = object.reference_joints();
  joints += Eigen::VectorXd::LinSpaced(joints.size(), -0.08, 0.1);
  ObjectState state = object.solve_from(joints, object.reference_positions());
  ASSERT_TRUE(state.statics().converged()) << state.statics().reason;
  const Eigen::MatrixXd dx_dz =
      object.force_response(state, space.force_derivatives(object, state, p));

  // Column by column, each coordinate stepped in units of its scale: a small column is checked
  // against its own size, not hidden by a large one.
  for (int k = 0; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    const auto moved = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      Eigen::VectorXd dz = Eigen::VectorXd::Zero(space.size());
      dz[k] = c.scale * u[0];
      return equilibrium(space.advanced(p, dz).applied_to(scene), joints, state.positions());
    };
    const Eigen::MatrixXd numeric =
        test::central_difference_jacobian(moved, Eigen::VectorXd::Zero(1), 1e-4);
    EXPECT_TRUE(
        test::derivative_matches(dx_dz.col(k) * c.scale, numeric, 1e-5, c.name, 1e-6 * c.scale));
  }
}

TEST(ParameterSpace, AppliedParametersRoundTripThroughTheScene) {
  const Scene scene = offset_scene();
  const PhysicalParameters p = PhysicalParameters::of(scene);
  EXPECT_NEAR(p.youngs_modulus, 5e4, 1e-6);
  EXPECT_NEAR(p.poisson_ratio, 0.3, 1e-12);
  const Scene again = p.applied_to(scene);
  EXPECT_NEAR(again.material.mu, scene.material.mu, 1e-9 * scene.material.mu);
  EXPECT_NEAR(again.material.kappa, scene.material.kappa, 1e-9 * scene.material.kappa);
  EXPECT_TRUE(again.grips[0].offset.isApprox(scene.grips[0].offset, 1e-15));
}

TEST(ParameterSpace, UnknownNamesAreRefused) {
  EXPECT_THROW(parse_fit_selection("youngs_modulus,stiffness"), std::invalid_argument);
  EXPECT_THROW(parse_fit_selection(""), std::invalid_argument);
  const FitSelection s = parse_fit_selection("density,grip_offsets");
  EXPECT_TRUE(s.density && s.grip_offsets && !s.youngs_modulus && !s.poisson_ratio);
}

}  // namespace
}  // namespace shapectl
