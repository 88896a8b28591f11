#include <shapectl/calib/model_parameters.hpp>

#include <gtest/gtest.h>

#include <shapectl/calib/equilibria.hpp>
#include <shapectl/calib/observation_residuals.hpp>
#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"
#include "support/linear_solvers.hpp"
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

// Force responses from each linear solver's factor (support/linear_solvers.hpp).
class ParameterSensitivity : public test::EachLinearSolver {};

TEST_P(ParameterSensitivity, EveryFittableParameterMatchesCentralDifferences) {
  const Scene scene = with_solver(offset_scene());
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

// A bar clamped at one end, sagging under gravity, placed off the world's origin and turned:
// moving its pose moves the clamp and turns gravity in the bar's frame.
Scene clamped_scene() {
  Scene scene;
  scene.source = "clamped_scene";
  scene.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({0.2, 0.03, 0.03}, {10, 2, 2}));
  scene.material = material_from_youngs(5e4, 0.3, 60);
  scene.T_world_object =
      Eigen::Translation3d(0.3, -0.1, 0.2) * Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized());
  scene.fixed =
      NodeSelection{.box = AlignedBox{Vec3(-0.101, -0.02, -0.02), Vec3(-0.089, 0.02, 0.02)},
                    .nodes = {}};
  scene.statics.relative_tolerance = 1e-12;
  return scene;
}

Positions clamped_equilibrium(const Scene& scene) {
  Positions x = scene.world_rest_positions();
  const StaticsResult r = ObjectStatics(scene).solve(x);
  EXPECT_TRUE(r.converged()) << r.reason;
  return x;
}

// The pose's columns: its rigid motion plus the response to the gravity it turns, without which
// the rotations about x and y would be off by 34 % and 4 % (measured errors ~1e-10).
TEST_P(ParameterSensitivity, MaterialAndPoseOfAClampedBarMatchCentralDifferences) {
  const Scene scene = with_solver(clamped_scene());
  const ParameterSpace space(
      scene, {.youngs_modulus = true, .poisson_ratio = true, .density = true, .object_pose = true});
  ASSERT_EQ(space.size(), 3 + 6);
  const PhysicalParameters p = PhysicalParameters::of(scene);
  const Observations two_frames{.frames = {ObservationFrame{}, ObservationFrame{}}};
  const Equilibria at =
      frame_equilibria(scene, space, p, two_frames, nullptr, {.with_sensitivity = true});
  ASSERT_EQ(at.frames.size(), 2u);
  EXPECT_EQ(at.frames[0], at.frames[1]);  // one equilibrium for every frame
  const Eigen::MatrixXd& dx_dz = at.frames[0]->dx_dz;
  EXPECT_TRUE(test::derivative_matches(at.frames[0]->positions, clamped_equilibrium(scene), 1e-9,
                                       "equilibrium"));

  for (int k = 0; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    const auto moved = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      Eigen::VectorXd dz = Eigen::VectorXd::Zero(space.size());
      dz[k] = c.scale * u[0];
      return clamped_equilibrium(space.advanced(p, dz).applied_to(scene));
    };
    const Eigen::MatrixXd numeric =
        test::central_difference_jacobian(moved, Eigen::VectorXd::Zero(1), 1e-4);
    EXPECT_TRUE(
        test::derivative_matches(dx_dz.col(k) * c.scale, numeric, 1e-5, c.name, 1e-6 * c.scale));
    // The rigid part alone is not it where the rotation turns gravity (about x and y).
    if (c.kind == ParameterCoordinate::Kind::PoseRotation && c.axis != 2) {
      EXPECT_FALSE(
          test::derivative_matches(space.pose_motion(at.frames[0]->positions, p).col(k) * c.scale,
                                   numeric, 1e-3, c.name));
    }
  }
}

// Issue 35: a frame of its own loads (a weight hung from the free end, pulling sideways too),
// the bar of two materials (its free half a region of its own): every material's columns, the
// region's included, and the pose's, whose rotation turns the loads with gravity in the bar's
// frame, match central differences of that frame's equilibria.
TEST_P(ParameterSensitivity, MaterialsRegionsAndPoseOfALoadedFrameMatchCentralDifferences) {
  Scene scene = with_solver(clamped_scene());
  scene.regions.push_back({.box = AlignedBox{Vec3(0, -1, -1), Vec3(1, 1, 1)},
                           .material = material_from_youngs(8e4, 0.35, 90)});
  ObservationFrame loaded;
  const NodeSelection free_end{.box = AlignedBox{Vec3(0.099, -1, -1), Vec3(1, 1, 1)}, .nodes = {}};
  loaded.loads = std::vector<NodeLoad>{
      {.nodes = free_end.resolve(*scene.object_mesh), .force = Vec3(0.005, 0.01, -0.04)}};
  const Observations frames{.frames = {ObservationFrame{}, loaded, loaded}};
  FitSelection all{.youngs_modulus = true,
                   .poisson_ratio = true,
                   .density = true,
                   .object_pose = true};
  for (const char* name : {"youngs_modulus", "poisson_ratio", "density"})
    all.regions.push_back({0, name});
  const ParameterSpace space(scene, all);
  ASSERT_EQ(space.size(), 3 + 6 + 3);
  EXPECT_EQ(space.coordinates()[3].name, "regions[0].youngs_modulus");
  const PhysicalParameters p = PhysicalParameters::of(scene);
  const Equilibria at =
      frame_equilibria(scene, space, p, frames, nullptr, {.with_sensitivity = true});
  ASSERT_EQ(at.frames.size(), 3u);
  EXPECT_NE(at.frames[0], at.frames[1]);  // another load case
  EXPECT_EQ(at.frames[1], at.frames[2]);  // the same one
  Scene with_loads = scene;
  with_loads.loads = *loaded.loads;
  // The load moves the tip by centimetres: the frame's equilibrium is under it.
  EXPECT_GT((at.frames[1]->positions - at.frames[0]->positions).cwiseAbs().maxCoeff(), 0.01);
  EXPECT_TRUE(test::derivative_matches(at.frames[1]->positions, clamped_equilibrium(with_loads),
                                       1e-9, "loaded equilibrium"));
  const Eigen::MatrixXd& dx_dz = at.frames[1]->dx_dz;
  for (int k = 0; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    const auto moved = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      Eigen::VectorXd dz = Eigen::VectorXd::Zero(space.size());
      dz[k] = c.scale * u[0];
      return clamped_equilibrium(space.advanced(p, dz).applied_to(with_loads));
    };
    const Eigen::MatrixXd numeric =
        test::central_difference_jacobian(moved, Eigen::VectorXd::Zero(1), 1e-4);
    EXPECT_TRUE(
        test::derivative_matches(dx_dz.col(k) * c.scale, numeric, 1e-5, c.name, 1e-6 * c.scale));
  }
}

INSTANTIATE_TEST_SUITE_P(Each, ParameterSensitivity, testing::ValuesIn(test::kLinearSolvers),
                         test::linear_solver_name);

TEST(ParameterSpace, AppliedParametersRoundTripThroughTheScene) {
  const Scene scene = offset_scene();
  const PhysicalParameters p = PhysicalParameters::of(scene);
  EXPECT_NEAR(p.youngs_modulus, 5e4, 1e-6);
  EXPECT_NEAR(p.poisson_ratio, 0.3, 1e-12);
  const Scene again = p.applied_to(scene);
  EXPECT_NEAR(again.material.mu, scene.material.mu, 1e-9 * scene.material.mu);
  EXPECT_NEAR(again.material.kappa, scene.material.kappa, 1e-9 * scene.material.kappa);
  EXPECT_TRUE(again.grips[0].offset.isApprox(scene.grips[0].offset, 1e-15));
  EXPECT_TRUE(again.T_world_object.isApprox(scene.T_world_object, 1e-15));
}

TEST(ParameterSpace, ObjectPoseMovesTheSceneAboutTheObjectsOrigin) {
  const Scene scene = clamped_scene();
  const ParameterSpace space(scene, {.object_pose = true});
  const PhysicalParameters p = PhysicalParameters::of(scene);
  Eigen::VectorXd dz(6);
  dz << 0.001, -0.002, 0.003, 0, 0, 0.05;
  const Eigen::Isometry3d moved = space.advanced(p, dz).object_pose;
  EXPECT_TRUE(moved.translation().isApprox(p.object_pose.translation() + dz.head<3>(), 1e-15));
  EXPECT_TRUE(moved.linear().isApprox(Eigen::AngleAxisd(0.05, Vec3::UnitZ()).toRotationMatrix() *
                                          p.object_pose.linear(),
                                      1e-15));
  EXPECT_EQ(space.coordinates()[5].name, "object_pose.rz");
}

// Why ParameterSpace refuses `fit` for `scene`, or "accepted".
std::string refusal(const Scene& scene, const FitSelection& fit) {
  try {
    ParameterSpace space(scene, fit);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

// The grips tie a gripped object to the grippers, which are where the joints put them.
TEST(ParameterSpace, ObjectPoseIsRefusedForAnObjectTheRobotHolds) {
  Scene gripped = offset_scene();
  EXPECT_NE(refusal(gripped, {.object_pose = true}).find("held by the robot's grips alone"),
            std::string::npos);
  gripped.fixed = clamped_scene().fixed;
  EXPECT_NE(refusal(gripped, {.object_pose = true}).find("as well as by fixed nodes"),
            std::string::npos);
  EXPECT_EQ(refusal(clamped_scene(), {.grip_offsets = true}),
            "grip_offsets: the scene has no grips");
  EXPECT_EQ(refusal(clamped_scene(), {.object_pose = true}), "accepted");
}

// With regions, youngs_modulus etc. are the object's own material's, each region's its own; a
// region the scene does not have is named. The pose turns the loads with the weight.
TEST(ParameterSpace, RegionMaterialsAreFittedAndAMissingRegionIsNamed) {
  Scene two_materials = clamped_scene();
  two_materials.regions.push_back({.box = AlignedBox{Vec3(-1, -1, -1), Vec3(0, 1, 1)},
                                   .material = material_from_youngs(1e6, 0.3, 40)});
  for (const char* fit : {"youngs_modulus", "poisson_ratio", "density", "regions[0].youngs_modulus",
                          "regions[0].density,object_pose"})
    EXPECT_EQ(refusal(two_materials, parse_fit_selection(fit)), "accepted") << fit;
  EXPECT_EQ(refusal(two_materials, parse_fit_selection("regions[1].youngs_modulus")),
            "regions[1].youngs_modulus: the scene has 1 region(s), regions[0] to regions[0]");
  EXPECT_EQ(refusal(clamped_scene(), parse_fit_selection("regions[0].poisson_ratio")),
            "regions[0].poisson_ratio: the scene has no \"regions\"");
  const PhysicalParameters p = PhysicalParameters::of(two_materials);
  ASSERT_EQ(p.regions.size(), 1u);
  EXPECT_NEAR(p.regions[0].youngs_modulus, 1e6, 1e-3);
  const ParameterSpace space(two_materials, parse_fit_selection("regions[0].youngs_modulus"));
  const Scene moved =
      space.advanced(p, Eigen::VectorXd::Constant(1, std::log(2.0))).applied_to(two_materials);
  EXPECT_NEAR(youngs_modulus_of(moved.regions[0].material), 2e6, 1e-3);
  EXPECT_NEAR(youngs_modulus_of(moved.material), youngs_modulus_of(two_materials.material), 1e-6);
  Scene loaded = clamped_scene();
  loaded.loads.push_back({.nodes = {3}, .force = Vec3(0, 0, -0.1)});
  EXPECT_EQ(refusal(loaded, {.object_pose = true}), "accepted");
}

TEST(ParameterSpace, UnknownNamesAreRefused) {
  EXPECT_THROW(parse_fit_selection("youngs_modulus,stiffness"), std::invalid_argument);
  EXPECT_THROW(parse_fit_selection(""), std::invalid_argument);
  const FitSelection s = parse_fit_selection("density,grip_offsets");
  EXPECT_TRUE(s.density && s.grip_offsets && !s.youngs_modulus && !s.poisson_ratio &&
              !s.object_pose);
  EXPECT_TRUE(parse_fit_selection("object_pose").object_pose);
  for (const char* bad : {"regions[].youngs_modulus", "regions[x].density", "regions[0].stiffness",
                          "regions[0]youngs_modulus", "regions[-1].density"})
    EXPECT_THROW(parse_fit_selection(bad), std::invalid_argument) << bad;
  const FitSelection r = parse_fit_selection("regions[2].poisson_ratio,youngs_modulus");
  ASSERT_EQ(r.regions.size(), 1u);
  EXPECT_EQ(r.regions[0].region, 2);
  EXPECT_EQ(r.regions[0].name, "poisson_ratio");
}

// A depth camera's pose correction moves its points, not the model: the residuals' camera
// columns (calib/observation_residuals.hpp) against central differences of the residuals,
// stepped through ParameterSpace::advanced from a correction already away from the identity.
TEST(ParameterSpace, CameraPoseColumnsMatchCentralDifferences) {
  const Scene scene = clamped_scene();
  const Positions x = clamped_equilibrium(scene);
  SurfaceDistance surface(scene.object_mesh->surface_triangles());
  surface.update(x);
  ObservationFrame frame;
  frame.camera = FrameCamera{1, Vec3(0.05, -0.4, 0.3)};
  std::mt19937 rng(7);
  std::normal_distribution<double> off(0, 0.003);
  for (std::size_t t = 0; t < surface.triangles().size(); t += 5) {
    Vec3 centroid = Vec3::Zero();
    for (int node : surface.triangles()[t]) centroid += x.segment<3>(3 * node) / 3;
    frame.points.push_back(centroid + Vec3(off(rng), off(rng), off(rng)));
  }
  const ParameterSpace space(scene, {.youngs_modulus = true, .camera_poses = true}, 2);
  ASSERT_EQ(space.size(), 1 + 12);
  EXPECT_EQ(space.coordinates()[12].name, "cameras[1].pose.rz");
  Eigen::VectorXd start = Eigen::VectorXd::Zero(space.size());
  start.tail<6>() << 0.002, -0.001, 0.003, 0.02, -0.01, 0.03;
  const PhysicalParameters p = space.advanced(PhysicalParameters::of(scene), start);
  const auto residuals_at = [&](const PhysicalParameters& q, const Eigen::MatrixXd& dx_dz) {
    // A cut-off of 1 m: every point an inlier on both sides of each step.
    return frame_residuals(frame, x, surface, 1.0, dx_dz,
                           space.camera_motion(1, frame.camera->position, q));
  };
  const Eigen::MatrixXd analytic =
      residuals_at(p, Eigen::MatrixXd::Zero(x.size(), space.size())).jacobian;
  EXPECT_TRUE(analytic.middleCols(1, 6).isZero()) << "camera 0 sees none of these points";
  for (int k = 7; k < space.size(); ++k) {
    const ParameterCoordinate& c = space.coordinates()[k];
    const auto moved = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      Eigen::VectorXd dz = Eigen::VectorXd::Zero(space.size());
      dz[k] = c.scale * u[0];
      return residuals_at(space.advanced(p, dz), Eigen::MatrixXd()).residuals;
    };
    const Eigen::MatrixXd numeric =
        test::central_difference_jacobian(moved, Eigen::VectorXd::Zero(1), 1e-6);
    EXPECT_TRUE(test::derivative_matches(analytic.col(k) * c.scale, numeric, 1e-6, c.name));
  }
}

}  // namespace
}  // namespace shapectl
