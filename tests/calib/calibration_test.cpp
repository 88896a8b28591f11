#include <shapectl/calib/calibration.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <random>
#include <string>
#include <thread>

#include <shapectl/calib/equilibria.hpp>
#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "calib/calibration_checks.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

// The YuMi holding the foam bar at one end (its sag shows the stiffness; held at both ends the
// bar's shape is set by the grippers, whatever its stiffness); the "real" bar is 1.8× stiffer
// and held 4 mm / 3° off.
struct SyntheticStudy {
  Scene model = load_scene(test::source_path("scenes/yumi_cantilever.json"));
  Scene truth = model;
  std::vector<Eigen::VectorXd> poses;

  SyntheticStudy() {
    truth.material =
        material_from_youngs(1.8 * PhysicalParameters::of(model).youngs_modulus,
                             PhysicalParameters::of(model).poisson_ratio, model.material.density);
    truth.grips[0].offset = Eigen::Translation3d(0.004 * Vec3(1, 1, -1).normalized()) *
                            Eigen::AngleAxisd(3 * M_PI / 180, Vec3(0, 1, 1).normalized());
    const Eigen::VectorXd reference = model.robot->reference_joints;
    Eigen::VectorXd a = reference, b = reference;
    a[0] += 0.15, a[6] += 0.5;  // the left shoulder swings, the wrist turns the bar
    b[3] -= 0.2, b[5] += 0.3;   // the elbow and the wrist tilt it
    poses = {reference, a, b};
  }

  Observations observe(const SimulatedCamera& camera, unsigned seed) const {
    const GrippedObject world(truth);
    std::mt19937 rng(seed);
    Observations out;
    for (const Eigen::VectorXd& joints : poses) {
      const ObjectState state = equilibrium_along_path(world, joints);
      out.frames.push_back(camera.observe(world.mesh(), state.positions(), joints, rng));
    }
    return out;
  }
};

std::vector<int> spread_nodes(int node_count, int count, unsigned seed) {
  std::vector<int> all(node_count);
  for (int i = 0; i < node_count; ++i) all[i] = i;
  std::shuffle(all.begin(), all.end(), std::mt19937(seed));
  return {all.begin(), all.begin() + count};
}

// 15 markers spread over the bar, 0.3 mm noise, at the study's three poses.
Observations fifteen_markers(const SyntheticStudy& study) {
  SimulatedCamera camera;
  camera.marker_nodes = spread_nodes(study.model.object_mesh->node_count(), 15, 7);
  camera.sigma = 0.0003;
  return study.observe(camera, 11);
}

void expect_truth_recovered(const SyntheticStudy& study, const CalibrationResult& r) {
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_TRUE(r.unidentified.empty()) << r.unidentified.front().held << " held";
  const double E_true = PhysicalParameters::of(study.truth).youngs_modulus;
  EXPECT_NEAR(r.fitted.youngs_modulus / E_true, 1, 0.03);
  for (std::size_t g = 0; g < study.truth.grips.size(); ++g)
    EXPECT_TRUE(
        test::motion_near(r.fitted.grip_offsets[g], study.truth.grips[g].offset, 0.0005, 0.5))
        << "grip " << g;
  test::expect_noise_level(r);
}

TEST(Calibration, RecoversStiffnessAndGripOffsetsFromFifteenMarkersAtThreePoses) {
  const SyntheticStudy study;
  const Observations observations = fifteen_markers(study);
  const CalibrationResult r =
      calibrate(study.model, observations, parse_fit_selection("youngs_modulus,grip_offsets"));
  expect_truth_recovered(study, r);
}

TEST(Calibration, RecoversTheSameFromPointCloudsWithOutliers) {
  const SyntheticStudy study;
  const Observations observations = study.observe(test::depth_camera_with_outliers(), 12);
  const CalibrationResult r =
      calibrate(study.model, observations, parse_fit_selection("youngs_modulus,grip_offsets"));
  expect_truth_recovered(study, r);
}

// Every trial of the fit is a new model (another stiffness, other grip offsets), the pattern of
// its Hessian the same. One trial makes the workspaces its frames' equilibria need at once (a
// walk from the reference joints holds two states); a whole fit on the same pool, every trial
// with a new GrippedObject, analyses nothing more.
TEST(Calibration, OneSymbolicAnalysisPerPatternNotOnePerTrial) {
  const SyntheticStudy study;
  const Observations observations = fifteen_markers(study);
  ASSERT_EQ(observations.frames.size(), 3u);
  const FitSelection fit = parse_fit_selection("youngs_modulus,grip_offsets");
  const auto pool = WorkspacePool::create();
  long long before = statics_totals().analyses;
  frame_equilibria(study.model, ParameterSpace(study.model, fit),
                   PhysicalParameters::of(study.model), observations, nullptr,
                   {.workspaces = pool});
  const long long one_trial = statics_totals().analyses - before;
  EXPECT_GE(one_trial, 1);
  EXPECT_LE(one_trial, 2);
  before = statics_totals().analyses;
  const CalibrationResult r =
      calibrate(study.model, observations, fit, {.max_seconds = 300, .workspaces = pool});
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_GE(r.iterations, 3);  // trials: at least one per iteration
  EXPECT_EQ(statics_totals().analyses - before, 0);
}

TEST(Calibration, StiffnessAndDensityFromShapeAloneAreReportedUnidentifiable) {
  const SyntheticStudy study;
  SimulatedCamera camera;
  camera.marker_nodes = spread_nodes(study.model.object_mesh->node_count(), 15, 7);
  const Observations observations = study.observe(camera, 13);
  const CalibrationResult r =
      calibrate(study.model, observations, parse_fit_selection("youngs_modulus,density"));
  EXPECT_EQ(r.parameters.size(), 2u);
  test::expect_density_held_for_stiffness(r);
}

// Seconds `f` took.
template <class F>
double seconds_of(F&& f) {
  const auto started = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

// Fine path steps make every frame's walk from the reference joints long (the default study
// takes seconds so): the budget must reach into the walk, not wait for it, and a cancel too.
TEST(Calibration, ATimeBudgetOrACancelStopsTheFitInsideTheWalkToAFrame) {
  const SyntheticStudy study;
  SimulatedCamera camera;
  camera.marker_nodes = spread_nodes(study.model.object_mesh->node_count(), 15, 7);
  const Observations observations = study.observe(camera, 11);
  const FitSelection fit = parse_fit_selection("youngs_modulus");
  std::string error;
  const auto stopped_fit = [&](const CalibrationOptions& options) {
    try {
      calibrate(study.model, observations, fit, options);
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
  };
  const double budgeted =
      seconds_of([&] { stopped_fit({.path_step = 0.001, .max_seconds = 0.3}); });
  EXPECT_EQ(error, "time limit of 0.3 s reached before the model was evaluated");
  EXPECT_LT(budgeted, 2.0);

  std::atomic<bool> cancel{false};
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    cancel = true;
  });
  const double cancelled =
      seconds_of([&] { stopped_fit({.path_step = 0.001, .cancel = &cancel}); });
  canceller.join();
  EXPECT_EQ(error, "cancelled before the model was evaluated");
  EXPECT_LT(cancelled, 2.0);
  // The messages above say the model was never evaluated: the bounds cut into the walk. It is
  // longer than them unbounded (one frame's walk alone: ~1 s on the 2-core CI machine), so
  // this test cannot pass on a walk that ends by itself within 0.3 s.
  Observations far_frame{{observations.frames[1]}};
  error.clear();
  EXPECT_GT(seconds_of([&] {
              calibrate(study.model, far_frame, fit, {.max_iterations = 1, .path_step = 0.001});
            }),
            0.3);
}

}  // namespace
}  // namespace shapectl
