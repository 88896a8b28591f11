// Calibration of a scene without a robot: the foam bar clamped at one end
// (scenes/foam_bar_clamped.json), every frame the same equilibrium seen with new noise.
#include <shapectl/calib/calibration.hpp>

#include <gtest/gtest.h>

#include <random>

#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "calib/calibration_checks.hpp"
#include "calib/depth_views.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

// The clamped foam bar, of a softer foam (50 kPa: the true bar sags 4 cm, the model 6 cm;
// see FixedCalibration.RecoversStiffnessAndClampPoseFromFifteenMarkers); the "real" bar is
// 1.5× stiffer than the scene says, and its clamp sits 3 mm and 2° off.
struct ClampedStudy {
  Scene model = load_scene(test::source_path("scenes/foam_bar_clamped.json"));
  Scene truth = model;

  ClampedStudy() {
    model.material =
        material_from_youngs(5e4, poisson_ratio_of(model.material), model.material.density);
    truth.material = material_from_youngs(1.5 * youngs_modulus_of(model.material),
                                          poisson_ratio_of(model.material), model.material.density);
    truth.T_world_object = Eigen::Translation3d(0.003 * Vec3(1, -1, 1).normalized()) *
                           Eigen::AngleAxisd(2 * M_PI / 180, Vec3(1, 2, -1).normalized()) *
                           model.T_world_object;
  }

  // Frames of the true equilibrium (no joints: the scene has no robot).
  Observations observe(const SimulatedCamera& camera, unsigned seed, int frames = 3) const {
    Positions x = truth.world_rest_positions();
    const ObjectStatics statics(truth);
    EXPECT_TRUE(statics.solve(x).converged());
    std::mt19937 rng(seed);
    Observations out;
    for (int frame = 0; frame < frames; ++frame)
      out.frames.push_back(camera.observe(statics.mesh(), x, Eigen::VectorXd(), rng));
    return out;
  }
};

// 15 markers: three around the bar (two top corners, the bottom's middle) at the clamp's end,
// where it leaves the clamp and at three stations on to the free end.
std::vector<int> markers_along_the_bar(const TetMesh& mesh) {
  std::vector<int> nodes;
  for (double x : {-0.16, -0.14, -0.06, 0.04, 0.16})
    for (const Vec3& at : {Vec3(x, -0.015, 0.015), Vec3(x, 0.015, 0.015), Vec3(x, 0, -0.015)})
      for (int i = 0; i < mesh.node_count(); ++i)
        if ((mesh.rest_positions()[i] - at).norm() < 1e-9) nodes.push_back(i);
  return nodes;
}

void expect_truth_recovered(const ClampedStudy& study, const CalibrationResult& r) {
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_TRUE(r.unidentified.empty()) << r.unidentified.front().held << " held";
  EXPECT_NEAR(r.fitted.youngs_modulus / youngs_modulus_of(study.truth.material), 1, 0.03);
  EXPECT_TRUE(test::motion_near(r.fitted.object_pose, study.truth.T_world_object, 0.0005, 0.5));
  EXPECT_TRUE(r.scene.T_world_object.isApprox(r.fitted.object_pose));
  test::expect_noise_level(r);
}

// Over the observed length, a stiffer bar looks much like a clamp tilted up and raised: the sag
// tells them apart only by its curvature. Standard deviation of E here: 0.7 % (10 frames of a
// 4 cm sag); 1.3 % with 3 frames; ~5 % with the scene's own 200 kPa foam (1 cm of sag) and 3
// frames. Ten frames: a third of a second of a 30 Hz tracker watching the still bar.
TEST(FixedCalibration, RecoversStiffnessAndClampPoseFromFifteenMarkers) {
  const ClampedStudy study;
  SimulatedCamera camera;
  camera.marker_nodes = markers_along_the_bar(*study.model.object_mesh);
  ASSERT_EQ(camera.marker_nodes.size(), 15u);
  camera.sigma = 0.0003;
  const CalibrationResult r = calibrate(study.model, study.observe(camera, 21, 10),
                                        parse_fit_selection("youngs_modulus,object_pose"));
  expect_truth_recovered(study, r);
  ASSERT_EQ(r.parameters.size(), 7u);
  EXPECT_EQ(r.parameters[4].name, "object_pose.rx");
  EXPECT_EQ(r.parameters[4].initial, 0);  // rotations are reported from the scene's pose
  EXPECT_GT(r.parameters[4].standard_deviation, 0);
  EXPECT_LT(r.parameters[0].standard_deviation, 0.01 * r.fitted.youngs_modulus);
}

// Every trial of the fit is a new model (another stiffness, another pose), the pattern of its
// Hessian the same: the fit's workspace pool keeps its one symbolic analysis.
TEST(FixedCalibration, OneSymbolicAnalysisPerPatternNotOnePerTrial) {
  const ClampedStudy study;
  SimulatedCamera camera;
  camera.marker_nodes = markers_along_the_bar(*study.model.object_mesh);
  camera.sigma = 0.0003;
  const Observations observations = study.observe(camera, 21, 3);
  const long long before = statics_totals().analyses;
  const CalibrationResult r =
      calibrate(study.model, observations, parse_fit_selection("youngs_modulus,object_pose"));
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_GE(r.iterations, 3);  // trials: at least one per iteration
  EXPECT_EQ(statics_totals().analyses - before, 1);
}

TEST(FixedCalibration, RecoversTheSameFromPointCloudsWithOutliers) {
  const ClampedStudy study;
  const CalibrationResult r =
      calibrate(study.model, study.observe(test::depth_camera_with_outliers(), 22),
                parse_fit_selection("youngs_modulus,object_pose"));
  expect_truth_recovered(study, r);
}

// A depth camera whose extrinsics are 6 mm off (every point shifted), 20 % outliers, the
// default fit (E and the object's pose, the pose under its default prior): the object's
// translation takes the offset, well within its 10 mm prior, the rotation stays within 1°, and
// E is within 5 %. With the priors off the same fit reports what E trades off with.
TEST(FixedCalibration, ACameraOffsetIsTakenByTheObjectTranslationWithinItsPrior) {
  ClampedStudy study;
  study.truth.T_world_object = study.model.T_world_object;  // only the camera is off
  const Vec3 offset = 0.006 * Vec3(2, -1, 2).normalized();
  Observations observations = study.observe(test::depth_camera_with_outliers(), 26);
  for (ObservationFrame& frame : observations.frames)
    for (Vec3& p : frame.points) p += offset;
  const FitSelection fit = parse_fit_selection("youngs_modulus,object_pose");
  const CalibrationResult r = calibrate(study.model, observations, fit);
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_NEAR(r.fitted.youngs_modulus / youngs_modulus_of(study.truth.material), 1, 0.05);
  const Eigen::Isometry3d moved = r.fitted.object_pose * study.model.T_world_object.inverse();
  EXPECT_LT((moved.translation() - offset).norm(), 0.001) << moved.translation().transpose();
  EXPECT_LT(Eigen::AngleAxisd(moved.linear()).angle(), M_PI / 180);
  for (const FittedParameter& p : r.parameters) EXPECT_FALSE(p.implausible) << p.name;

  // Without priors: a cloud this dense determines the pose by itself, so nothing trades off
  // with E here (the sparse-marker case where a free pose does: CalibrationPriors tests).
  CalibrationOptions no_priors;
  no_priors.priors = CalibrationPriors::none();
  const CalibrationResult free = calibrate(study.model, observations, fit, no_priors);
  ASSERT_TRUE(free.converged) << free.reason;
  EXPECT_NEAR(free.fitted.youngs_modulus / youngs_modulus_of(study.truth.material), 1, 0.05);
  EXPECT_EQ(free.parameters[0].verdict, Verdict::Determined);
  const Eigen::Isometry3d free_moved =
      free.fitted.object_pose * study.model.T_world_object.inverse();
  EXPECT_LT((free_moved.translation() - offset).norm(), 0.001);
}

// The same 6 mm, as a depth camera's pose given 6 mm off (its points all shifted by it), 20 %
// flying pixels. Fitted, the camera's pose and the object's translation share it within their
// priors; without priors the translations trade off exactly, and the report says so.
TEST(FixedCalibration, ADepthCameraOffsetIsTakenByTheCameraPoseWithinItsPrior) {
  ClampedStudy study;
  study.truth.T_world_object = study.model.T_world_object;  // only the camera is off
  const Vec3 offset = 0.006 * Vec3(2, -1, 2).normalized();
  Positions x = study.truth.world_rest_positions();
  ASSERT_TRUE(ObjectStatics(study.truth).solve(x).converged());
  const test::DepthCamera camera = test::bar_camera();
  const Eigen::Isometry3d stated = Eigen::Translation3d(offset) * camera.pose;
  std::mt19937 rng(26);
  Observations observations;
  for (int k = 0; k < 3; ++k) {
    ObservationFrame frame;
    const DepthImage image =
        test::seen_depth(camera, *study.model.object_mesh, x, 0.0003, 0.2, rng);
    frame.points = back_project(image, camera.intrinsics, stated, 2);
    frame.sigma = 0.0003;
    frame.camera = FrameCamera{0, stated.translation()};
    observations.frames.push_back(frame);
  }
  ASSERT_GT(observations.frames[0].points.size(), 1000u);
  const FitSelection fit = parse_fit_selection("youngs_modulus,object_pose,camera_poses");
  const CalibrationResult r = calibrate(study.model, observations, fit);
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_NEAR(r.fitted.youngs_modulus / youngs_modulus_of(study.truth.material), 1, 0.05);
  const Eigen::Isometry3d moved = r.fitted.object_pose * study.model.T_world_object.inverse();
  const CameraMotion motion =
      ParameterSpace(study.model, fit, 1).camera_motion(0, stated.translation(), r.fitted);
  // The bar's true points, seen through the stated pose and the fitted correction, are where the
  // fitted model puts them.
  for (const Vec3& q : {Vec3(-0.15, 0, 0), Vec3(0, 0, -0.01), Vec3(0.15, 0, -0.03)})
    EXPECT_LT((moved.inverse() * (motion.motion * (q + offset)) - q).norm(), 0.001) << q;
  EXPECT_LT(Eigen::AngleAxisd(moved.linear()).angle(), M_PI / 180);
  EXPECT_LT(Eigen::AngleAxisd(r.fitted.camera_pose(0).linear()).angle(), M_PI / 180);
  EXPECT_GT(r.fitted.camera_pose(0).translation().norm(), 0.001) << "the camera took its share";
  for (const FittedParameter& p : r.parameters) EXPECT_FALSE(p.implausible) << p.name;

  // Without priors the camera's and the object's translations move the points alike: not
  // determined, each named as the other's trade-off.
  CalibrationOptions no_priors;
  no_priors.priors = CalibrationPriors::none();
  const CalibrationResult free = calibrate(study.model, observations, fit, no_priors);
  EXPECT_NEAR(free.fitted.youngs_modulus / youngs_modulus_of(study.truth.material), 1, 0.05);
  int flagged = 0;
  for (const FittedParameter& p : free.parameters) {
    const bool camera = p.name.rfind("cameras[0].pose.", 0) == 0;
    const bool pose = p.name.rfind("object_pose.", 0) == 0;
    if (!(camera || pose) || p.verdict == Verdict::Determined) continue;
    for (const std::string& other : p.trades_off_with)
      if (other.rfind(camera ? "object_pose." : "cameras[0].pose.", 0) == 0) ++flagged;
  }
  EXPECT_GE(flagged, 3) << "the three translations at least";
}

// Held by a clamp, the bar's shape depends on stiffness and density through E/ρ alone.
TEST(FixedCalibration, StiffnessAndDensityFromShapeAloneAreReportedUnidentifiable) {
  const ClampedStudy study;
  SimulatedCamera camera;
  camera.marker_nodes = markers_along_the_bar(*study.model.object_mesh);
  const CalibrationResult r = calibrate(study.model, study.observe(camera, 23),
                                        parse_fit_selection("youngs_modulus,density,object_pose"));
  test::expect_density_held_for_stiffness(r);
  EXPECT_TRUE(r.converged) << r.reason;
}

// Markers on the clamped end only: they see where the clamp is, but the sag of the free end
// that shows the stiffness is not observed.
TEST(FixedCalibration, StiffnessSeenByNoMarkerIsHeld) {
  const ClampedStudy study;
  SimulatedCamera camera;
  for (int i = 0; i < study.model.object_mesh->node_count(); ++i)
    if (study.model.object_mesh->rest_positions()[i].x() < -0.139) camera.marker_nodes.push_back(i);
  const CalibrationResult r = calibrate(study.model, study.observe(camera, 24),
                                        parse_fit_selection("youngs_modulus,object_pose"));
  ASSERT_EQ(r.unidentified.size(), 1u);
  EXPECT_EQ(r.unidentified[0].held, "youngs_modulus");
}

TEST(FixedCalibration, FramesWithJointsAreRefused) {
  const ClampedStudy study;
  SimulatedCamera camera;
  camera.marker_nodes = {5};
  Observations observations = study.observe(camera, 25);
  observations.frames[1].joints = Eigen::VectorXd::Zero(2);
  EXPECT_THROW(calibrate(study.model, observations, parse_fit_selection("youngs_modulus")),
               std::invalid_argument);
}

}  // namespace
}  // namespace shapectl
