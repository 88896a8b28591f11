// The closed loop's slow half: calibration from the observed frames while the controller runs,
// the new model handed over without a jump in the joints.
#include <shapectl/calib/online_calibration.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <thread>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/observation_receiver.hpp>
#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/control/model_error_feedback.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "calib/different_world.hpp"
#include "support/test_support.hpp"
#include "support/wait_bound.hpp"

namespace shapectl {
namespace {

using test::true_error;

class OnlineCalibrationTest : public ::testing::Test {
 protected:
  OnlineCalibrationTest() {
    Eigen::VectorXd goal = model.robot->reference_joints;
    goal[0] -= 0.03, goal[7] += 0.03;  // the shoulders turn in: the bar arches
    const ObjectState at_goal = equilibrium_along_path(GrippedObject(model), goal);
    for (int node = 0; node < model.object_mesh->node_count(); node += 37)
      targets.nodes.push_back(node),
          targets.positions.push_back(at_goal.positions().segment<3>(3 * node));
    camera.marker_nodes = targets.nodes;
  }

  // The world at `joints` (from its last shape, the gripped nodes carried along as the real
  // object's are) and a frame of it.
  ObservationFrame look(const Eigen::VectorXd& joints) {
    Positions x = truth.positions();
    world.carry_gripped_nodes(truth.joints(), joints, truth.positions(), x);
    truth = world.solve_from(joints, x);
    EXPECT_TRUE(truth.statics().converged()) << truth.statics().reason;
    return camera.observe(world.mesh(), truth.positions(), joints, rng);
  }

  const Scene model = load_scene(test::source_path("scenes/yumi_bar.json"));
  const GrippedObject world{test::different_world(model)};
  ObjectState truth = equilibrium_along_path(world, model.robot->reference_joints);
  ShapeTargets targets;
  SimulatedCamera camera;
  std::mt19937 rng{9};
};

// The controller's loop with the calibration beside it: the optimizer iterates, the world
// settles at its joints, the camera's frames come back; calibrations run when due.
TEST_F(OnlineCalibrationTest, TheCalibratedModelPredictsTheWorldAndTheLoopReachesTheTargets) {
  // Frames as fast as this machine steps: the feedback's rate bound, by the wall clock, would
  // make the loop's path depend on the machine's speed (ClosedLoop's test says the same).
  ControllerOptions options;
  options.feedback.max_correction_rate = INFINITY;
  Controller controller(model, options);
  OnlineCalibrationOptions calibration_options{.period = 0.5};
  // The fit's deadline is a wall clock's: under TSan (5-15x slower) an 8-iteration fit passed it.
  calibration_options.calibration.max_seconds = test::wait_bound(30);
  OnlineCalibration calibration(controller, model, calibration_options);
  controller.set_targets(targets);
  controller.set_feedback(true);
  double first_model_error = 0;
  std::shared_ptr<const ControllerSnapshot> s;
  for (int frame = 0; frame < 30; ++frame) {
    for (int k = 0; k < 3; ++k) controller.step_once();
    s = controller.snapshot();
    ASSERT_TRUE(s->safe);
    calibration.observe(look(s->joints));
    calibration.poll(0.1 * frame);
    calibration.wait();  // deterministic: the result is handed over at the next poll
    if (frame == 2) {
      controller.step_once();
      first_model_error = controller.snapshot()->model_error;
    }
  }
  calibration.poll(3.0);
  controller.step_once();
  s = controller.snapshot();
  const OnlineCalibrationStatus c = calibration.status();
  ASSERT_GE(c.applied_runs, 1u) << c.error;
  EXPECT_EQ(s->model_updates, c.applied_runs);
  ASSERT_TRUE(c.result) << c.error;
  EXPECT_LT(c.result->rms_after, c.result->rms_before);
  EXPECT_EQ(c.applied_runs, c.runs) << c.error;  // every window had an equilibrium and a fit
  EXPECT_GT(first_model_error, 2e-3);  // the scene's model misses the world by millimetres...
  EXPECT_LT(s->model_error, 1e-3);     // ...the calibrated one predicts it at the noise level
  EXPECT_LT(true_error(targets, truth.positions()), 1e-3);
  EXPECT_EQ(s->observations, 30u);
  EXPECT_EQ(s->observations_ignored, 0u);
}

TEST_F(OnlineCalibrationTest, ANewModelKeepsTheJointsAndChangesTheShape) {
  Controller controller(model);
  controller.set_paused(true);
  controller.step_once();
  const auto before = controller.snapshot();
  controller.set_model(world.scene());
  controller.step_once();
  const auto after = controller.snapshot();
  EXPECT_EQ(after->model_updates, 1u);
  EXPECT_EQ(after->joints, before->joints);  // bit for bit: no jump
  EXPECT_GT((after->positions - before->positions).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_DOUBLE_EQ(youngs_modulus_of(after->material), youngs_modulus_of(world.scene().material));
  EXPECT_TRUE(after->grip_offsets[0].isApprox(world.scene().grips[0].offset));
  // The new model's equilibrium at those joints is the world's.
  const ObjectState world_there = world.solve_from(after->joints, after->positions);
  EXPECT_LT((after->positions - world_there.positions()).cwiseAbs().maxCoeff(), 1e-6);

  Scene other = model;
  other.grips.pop_back();
  EXPECT_THROW(controller.set_model(other), InputError);
}

TEST(ModelErrorFeedback, AModelChangeMovesTheEstimateSoThatTheBelievedShapeStays) {
  const Scene scene = load_scene(test::source_path("scenes/yumi_bar.json"));
  ModelErrorFeedback feedback(scene.object_mesh, {.gain = 1});
  const Positions before = scene.world_rest_positions();
  Positions observed = before, after = before;
  observed.segment<3>(0) += Vec3(0.003, 0, 0);
  after.segment<3>(0) += Vec3(0.002, 0.001, 0);
  feedback.observe({{0, observed.segment<3>(0)}}, before, 0.001, 0);
  feedback.model_changed(before, after);
  // x̂ + ê is what the loop believes the object's shape is: unchanged by the new model.
  EXPECT_LT((after.segment<3>(0) + feedback.estimate(0) - observed.segment<3>(0)).norm(), 1e-15);
}

TEST_F(OnlineCalibrationTest, TheWindowKeepsDistinctPosesAndNothingStartsWithoutFrames) {
  Controller controller(model);
  OnlineCalibration calibration(controller, model, {.automatic = false, .window = 3});
  std::string why;
  EXPECT_FALSE(calibration.start(&why));
  EXPECT_EQ(why, "no observed frames yet");
  Eigen::VectorXd joints = model.robot->reference_joints;
  calibration.observe(look(joints));
  calibration.observe(look(joints));  // the robot stands still: the newest frame replaces
  EXPECT_EQ(calibration.status().frames, 1);
  for (int k = 1; k <= 4; ++k) {
    joints[0] -= 0.01;
    calibration.observe(look(joints));
  }
  EXPECT_EQ(calibration.status().frames, 3);  // the window's size
  calibration.poll(100);                      // not automatic: nothing starts
  EXPECT_FALSE(calibration.status().running);
  EXPECT_EQ(calibration.status().runs, 0u);
}

TEST_F(OnlineCalibrationTest, ARobotCreepingInSmallStepsAddsAPoseEverySamePoseDistance) {
  // Steps of 0.002 rad, each within same_pose (0.005) of the one before: a pose is added once
  // the robot is 0.006 rad from where the newest pose was first seen (at 0.006, 0.012, 0.018).
  Controller controller(model);
  OnlineCalibration calibration(controller, model, {.automatic = false});
  ASSERT_EQ(calibration.options().same_pose, 0.005);
  Eigen::VectorXd joints = model.robot->reference_joints;
  calibration.observe(look(joints));
  for (int k = 1; k <= 10; ++k) {
    joints[0] -= 0.002;
    calibration.observe(look(joints));
  }
  EXPECT_EQ(calibration.status().frames, 4);
}

// One marker from one pose is 3 numbers: no fit of 13 parameters starts from it (it would
// "explain" the noise exactly and make the model worse elsewhere).
TEST_F(OnlineCalibrationTest, TooFewObservedNumbersForTheParametersStartNothing) {
  Controller controller(model);
  OnlineCalibration calibration(controller, model, {.period = 0});
  camera.marker_nodes = {targets.nodes[0]};
  calibration.observe(look(model.robot->reference_joints));
  std::string why;
  EXPECT_FALSE(calibration.start(&why));
  EXPECT_EQ(why,
            "too few observations: 3 measured numbers for 13 parameters (at least 39: more "
            "markers, or frames at other poses)");
  for (int k = 0; k < 3; ++k) calibration.observe(look(model.robot->reference_joints));
  calibration.poll(1);  // due, but refused: the status says why
  EXPECT_FALSE(calibration.status().running);
  EXPECT_EQ(calibration.status().error, why);
}

// Markers on gripped nodes only see where the grippers hold the bar, not how it bends: the
// stiffness cannot be told from them, and such a fit is never handed to the controller.
TEST_F(OnlineCalibrationTest, AFitOfNothingIdentifiableIsNotApplied) {
  Controller controller(model);
  OnlineCalibration calibration(controller, model,
                                {.fit = {.youngs_modulus = true,
                                         .poisson_ratio = false,
                                         .density = false,
                                         .grip_offsets = false},
                                 .automatic = false});
  camera.marker_nodes = {model.grips[0].nodes[0], model.grips[1].nodes[0]};
  calibration.observe(look(model.robot->reference_joints));
  ASSERT_TRUE(calibration.start());
  calibration.wait();
  calibration.poll(0);
  const OnlineCalibrationStatus c = calibration.status();
  EXPECT_EQ(c.runs, 1u);
  EXPECT_FALSE(c.applied);
  EXPECT_NE(c.error.find("no parameter is identifiable"), std::string::npos) << c.error;
  controller.step_once();
  EXPECT_EQ(controller.snapshot()->model_updates, 0u);
}

// Lying frames in the window (issue 32): a fit of them must not reach the controller.
class LyingWindowTest : public OnlineCalibrationTest {
 protected:
  // Calibrates three frames at distinct poses, each marker moved by `lie(k)`; the status.
  OnlineCalibrationStatus calibrate_lies(const std::function<Vec3(std::size_t)>& lie) {
    OnlineCalibration calibration(controller, model, {.automatic = false});
    for (int pose = 0; pose < 3; ++pose) {
      Eigen::VectorXd joints = model.robot->reference_joints;
      joints[0] -= 0.01 * pose, joints[7] += 0.01 * pose;
      ObservationFrame frame = look(joints);
      for (std::size_t k = 0; k < frame.markers.size(); ++k) frame.markers[k].position += lie(k);
      calibration.observe(frame);
    }
    EXPECT_TRUE(calibration.start());
    calibration.wait();
    calibration.poll(0);
    controller.step_once();
    EXPECT_EQ(controller.snapshot()->model_updates, 0u);
    return calibration.status();
  }
  Controller controller{model};
};

TEST_F(LyingWindowTest, AFitOfMarkersFiveToThreeHundredMillimetresOffIsNotApplied) {
  std::mt19937 lies(32);
  std::uniform_real_distribution<double> log_size(std::log(0.005), std::log(0.3));
  std::normal_distribution<double> normal;
  std::vector<Vec3> offsets;
  for (std::size_t k = 0; k < targets.nodes.size(); ++k)
    offsets.push_back(std::exp(log_size(lies)) *
                      Vec3(normal(lies), normal(lies), normal(lies)).normalized());
  const OnlineCalibrationStatus c = calibrate_lies([&](std::size_t k) { return offsets[k]; });
  EXPECT_EQ(c.runs, 1u);
  EXPECT_FALSE(c.applied);
  EXPECT_NE(c.error.find("not applied: the fit leaves chi2/dof"), std::string::npos) << c.error;
}

// A lie a model can explain: every marker 3 cm to the side is both grips holding the bar 3 cm
// off. The fit explains it to the noise, and is refused for the jump.
TEST_F(LyingWindowTest, AFitThatExplainsTheLieByAnImplausibleModelIsNotApplied) {
  const OnlineCalibrationStatus c = calibrate_lies([](std::size_t) { return Vec3(0, 0.03, 0); });
  ASSERT_TRUE(c.result) << c.error;
  EXPECT_LT(c.result->rms_after, c.result->rms_before);
  EXPECT_FALSE(c.applied);
  EXPECT_NE(c.error.find("not applied: beyond the bounds from the scene's values: grip_offsets["),
            std::string::npos)
      << c.error;
}

TEST(ModelBounds, AValueBeyondItsBoundIsNamedWithItsNumbers) {
  PhysicalParameters a;
  a.youngs_modulus = 1e5, a.poisson_ratio = 0.3, a.density = 40;
  a.grip_offsets = {Eigen::Isometry3d::Identity()};
  EXPECT_EQ(beyond_bounds(a, a, {}), "");
  PhysicalParameters b = a;
  b.youngs_modulus = 2.5e5;
  EXPECT_EQ(beyond_bounds(a, b, {}), "youngs_modulus 2.5e+05 Pa is 2.50x 1e+05 Pa (at most 2x)");
  b = a, b.youngs_modulus = 0.45e5;  // a factor 2.2 down
  EXPECT_NE(beyond_bounds(a, b, {}).find("youngs_modulus"), std::string::npos);
  b = a, b.density = 70;
  EXPECT_NE(beyond_bounds(a, b, {}).find("density"), std::string::npos);
  b = a, b.poisson_ratio = 0.45;
  EXPECT_EQ(beyond_bounds(a, b, {}), "poisson_ratio 0.450 is +0.150 from 0.300 (at most 0.1)");
  b = a,
  b.grip_offsets[0] = Eigen::Translation3d(0, 0.009, 0) * Eigen::AngleAxisd(0.09, Vec3::UnitZ());
  EXPECT_EQ(beyond_bounds(a, b, {}), "");
  b.grip_offsets[0] = Eigen::AngleAxisd(0.12, Vec3::UnitZ());
  EXPECT_EQ(beyond_bounds(a, b, {}),
            "grip_offsets[0] moved 0.0 mm and 0.120 rad (at most 10.0 mm, 0.100 rad)");
  b = a, b.youngs_modulus = NAN;
  EXPECT_NE(beyond_bounds(a, b, {}), "");
}

// A session must never stay "calibrating" (issue 32): cancel() stops a long fit at its next
// check, the status says so, and the next calibration may start.
TEST_F(OnlineCalibrationTest, CancelStopsARunningCalibrationAtItsNextCheck) {
  Controller controller(model);
  OnlineCalibrationOptions options{.fit = {.youngs_modulus = true,
                                           .poisson_ratio = false,
                                           .density = false,
                                           .grip_offsets = false},
                                   .automatic = false};
  options.calibration.path_step = 0.00005;  // 600 steps to the frame's joints: seconds
  OnlineCalibration calibration(controller, model, options);
  Eigen::VectorXd arched = model.robot->reference_joints;
  arched[0] -= 0.03, arched[7] += 0.03;
  calibration.observe(look(arched));
  ASSERT_TRUE(calibration.start());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(calibration.status().running);
  const auto cancelled = std::chrono::steady_clock::now();
  calibration.cancel();
  calibration.wait();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - cancelled).count(),
            1.0);
  calibration.poll(0);
  const OnlineCalibrationStatus c = calibration.status();
  EXPECT_FALSE(c.running);
  EXPECT_EQ(c.runs, 1u);
  EXPECT_FALSE(c.applied);
  EXPECT_NE(c.error.find("cancelled"), std::string::npos) << c.error;
  EXPECT_TRUE(calibration.start());  // the destructor cancels this one
}

TEST(ObservationReceiver, GoodDatagramsBecomeFramesAndBadOnesAreCountedWithTheirReason) {
  const Scene scene = load_scene(test::source_path("scenes/yumi_bar.json"));
  ObservationReceiver receiver("127.0.0.1", 0,
                               {.node_count = scene.object_mesh->node_count(),
                                .robot = scene.robot->model.get(),
                                .allow_points_files = true});  // refused all the same
  nlohmann::json joints = nlohmann::json::object();
  const auto& names = scene.robot->model->active_joint_names();
  for (std::size_t j = 0; j < names.size(); ++j)
    joints[names[j]] = scene.robot->reference_joints[static_cast<Eigen::Index>(j)];
  const nlohmann::json good = {{"joints", joints},
                               {"markers", {{{"node", 3}, {"position", {0.4, 0.0, 0.3}}}}},
                               {"time", 1.5}};
  nlohmann::json unknown_node = good, points_file = good;
  unknown_node["markers"][0]["node"] = 1 << 20;
  points_file["points_file"] = "/etc/passwd";
  UdpSocket sender("127.0.0.1", 0, "test sender");
  const sockaddr_in to = ipv4_address("127.0.0.1", receiver.port(), "test");
  const std::string too_deep = "[[[[[[[[[[]]]]]]]]]]";
  const std::vector<std::string> datagrams = {good.dump(),        "{not json", unknown_node.dump(),
                                              points_file.dump(), too_deep,    good.dump()};
  for (const std::string& datagram : datagrams) ASSERT_TRUE(sender.send_to(datagram, to));
  std::vector<ObservationFrame> frames;
  // Loopback: at once, in order.
  for (int k = 0; k < 200 && receiver.received() + receiver.rejected() < 6; ++k) {
    for (ObservationFrame& f : receiver.receive()) frames.push_back(std::move(f));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(receiver.received(), 2u);  // each datagram counts once: received or rejected
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].markers.at(0).node, 3);
  EXPECT_EQ(frames[0].time, 1.5);
  EXPECT_EQ(receiver.rejected(), 4u);
  // The last rejection names the sender and what was wrong.
  EXPECT_NE(receiver.last_rejection().find("udp 127.0.0.1:"), std::string::npos);
  EXPECT_NE(receiver.last_rejection().find("nested deeper"), std::string::npos)
      << receiver.last_rejection();
}

// `run --observations-udp` once took such a frame as received (issue 32): calibration then
// walked the model from the reference joints towards 1e6 rad for hours.
TEST(ObservationReceiver, AFrameWithAJointAtAMillionRadiansIsRejectedNotReceived) {
  const Scene scene = load_scene(test::source_path("scenes/yumi_bar.json"));
  ObservationReceiver receiver("127.0.0.1", 0,
                               {.node_count = scene.object_mesh->node_count(),
                                .robot = scene.robot->model.get()});
  nlohmann::json joints = nlohmann::json::object();
  const auto& names = scene.robot->model->active_joint_names();
  for (std::size_t j = 0; j < names.size(); ++j)
    joints[names[j]] = scene.robot->reference_joints[static_cast<Eigen::Index>(j)];
  joints[names[2]] = 1e6;
  const nlohmann::json far = {{"joints", joints},
                              {"markers", {{{"node", 3}, {"position", {0.4, 0.0, 0.3}}}}}};
  UdpSocket sender("127.0.0.1", 0, "test sender");
  ASSERT_TRUE(sender.send_to(far.dump(), ipv4_address("127.0.0.1", receiver.port(), "test")));
  std::vector<ObservationFrame> frames;
  for (int k = 0; k < 200 && receiver.rejected() == 0; ++k) {
    for (ObservationFrame& f : receiver.receive()) frames.push_back(std::move(f));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(receiver.received(), 0u);
  EXPECT_EQ(receiver.rejected(), 1u);
  EXPECT_NE(receiver.last_rejection().find("joints." + names[2] +
                                           ": expected a value within the joint's limits"),
            std::string::npos)
      << receiver.last_rejection();
}

}  // namespace
}  // namespace shapectl
