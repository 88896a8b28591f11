#pragma once
// What the calibration tests ask of a fit to synthetic data: the truth's rigid motions
// recovered within a tolerance, and residuals at the noise level.
#include <gtest/gtest.h>

#include <cmath>

#include <shapectl/calib/calibration.hpp>
#include <shapectl/calib/simulated_camera.hpp>

namespace shapectl::test {

// A fitted rigid motion (grip offset, object pose) within `metres` and `degrees` of the truth.
inline ::testing::AssertionResult motion_near(const Eigen::Isometry3d& fitted,
                                              const Eigen::Isometry3d& truth, double metres,
                                              double degrees) {
  const double off = (fitted.translation() - truth.translation()).norm();
  const double turned =
      Eigen::AngleAxisd(fitted.linear() * truth.linear().transpose()).angle() * 180 / M_PI;
  if (off <= metres && turned <= degrees) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << off * 1e3 << " mm and " << turned << "° off the truth (tolerance " << metres * 1e3
         << " mm, " << degrees << "°)";
}

// Residuals at the noise level: χ² per degree of freedom near 1, far below the start.
inline void expect_noise_level(const CalibrationResult& r) {
  EXPECT_GT(r.chi_squared_per_dof, 0.7);
  EXPECT_LT(r.chi_squared_per_dof, 1.3);
  EXPECT_GT(r.rms_before, 5 * r.rms_after);
}

// A depth camera: 1,500 points a frame on the surface, 20 % of them outliers, 0.3 mm noise.
inline SimulatedCamera depth_camera_with_outliers() {
  SimulatedCamera camera;
  camera.surface_points = 1500;
  camera.outlier_fraction = 0.2;
  camera.sigma = 0.0003;
  return camera;
}

// Stiffness and density asked for from shape alone (the first two parameters): one direction
// the data cannot determine, made of the two, with density held at its initial value: "not
// determined", trading off with Young's modulus, a different load suggested; E fitted.
inline void expect_density_held_for_stiffness(const CalibrationResult& r) {
  ASSERT_EQ(r.unidentified.size(), 1u);
  EXPECT_EQ(r.unidentified[0].held, "density");
  ASSERT_EQ(r.unidentified[0].combination.size(), 2u);  // youngs_modulus and density together
  EXPECT_NE(r.unidentified[0].suggestion.find("different load"), std::string::npos);
  ASSERT_GE(r.parameters.size(), 2u);
  EXPECT_FALSE(r.parameters[0].held);
  EXPECT_NE(r.parameters[0].verdict, Verdict::NotDetermined);
  EXPECT_TRUE(r.parameters[1].held);
  EXPECT_EQ(r.parameters[1].verdict, Verdict::NotDetermined);
  EXPECT_EQ(r.parameters[1].trades_off_with, std::vector<std::string>{"youngs_modulus"});
  EXPECT_NE(r.parameters[1].suggestion.find("hanging weight"), std::string::npos);
  EXPECT_EQ(r.parameters[1].fitted, r.parameters[1].initial);
}

}  // namespace shapectl::test
