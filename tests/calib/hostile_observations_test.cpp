// Lying observations against an armed robot (issue 32): the simulated world is held by the sim
// robot at its measured joints, its camera's frames are falsified before they reach the loop
// (feedback and online calibration), and at every sample, in transit too, the robot's joints
// must stay in the trust region around the open loop's and the world's true error within the
// open loop's plus the bound B that region allows (docs/calibration.md, "Safety: what an
// observation can make the robot do"), with the gate counting what it refused.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <thread>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/online_calibration.hpp>
#include <shapectl/calib/simulated_world.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "calib/different_world.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

using Clock = std::chrono::steady_clock;
// Falsifies a frame in place; `count` is the frame's number.
using Lie = std::function<void(ObservationFrame& frame, int count)>;

class HostileObservations : public ::testing::Test {
 protected:
  HostileObservations() {
    Eigen::VectorXd goal = model.robot->reference_joints;
    goal[0] -= 0.03, goal[7] += 0.03;  // the shoulders turn in: the bar arches
    const Positions arch = equilibrium_along_path(GrippedObject(model), goal).positions();
    for (int node = 0; node < model.object_mesh->node_count(); node += 37)
      targets.nodes.push_back(node), targets.positions.push_back(arch.segment<3>(3 * node));
    // Each marker its own direction, the same in every lying frame (a consistent lie is the
    // harder one: noise averages out).
    std::mt19937 rng(32);
    std::normal_distribution<double> normal;
    for (std::size_t k = 0; k < targets.nodes.size(); ++k)
      directions.push_back(Vec3(normal(rng), normal(rng), normal(rng)).normalized());
  }

  // Every marker `size` (m) off along its direction.
  void falsify(ObservationFrame& frame, double size) const {
    for (std::size_t k = 0; k < frame.markers.size(); ++k)
      frame.markers[k].position += size * directions[k % directions.size()];
  }
  // 5-300 mm, log-uniform, a new size each frame: some inside the gate, most outside.
  double lie_size() {
    return std::exp(std::uniform_real_distribution<double>(std::log(0.005), std::log(0.3))(sizes));
  }

  // The bound B on how much the world's true error (a mean over the target nodes) may exceed
  // the open loop's while every joint stays within `radius` of `joints`: the largest mean
  // displacement of the target nodes over that box, to first order, r · max over the box's
  // corners of mean_k |Σ_j ±∂y_k/∂θ_j| (a norm of a linear map is largest at a corner). The
  // world's own sensitivity, at the joints the loop starts from, not a number copied from the
  // docs (48 mm there for this world).
  double bound(const Eigen::VectorXd& joints, const Positions& near, double radius) const {
    const GrippedObject truth(test::different_world(model));
    ObjectState at = truth.solve_from(joints, near);
    EXPECT_TRUE(at.statics().converged()) << at.statics().reason;
    const Eigen::MatrixXd dy = truth.sensitivity(at);
    const auto m = dy.cols();
    double largest = 0;
    for (long corner = 0; corner < (1L << m); ++corner) {
      double sum = 0;
      for (int node : targets.nodes) {
        Vec3 d = Vec3::Zero();
        for (Eigen::Index j = 0; j < m; ++j)
          d += ((corner >> j) & 1 ? 1.0 : -1.0) * dy.block<3, 1>(3 * node, j);
        sum += d.norm();
      }
      largest = std::max(largest, sum / targets.size());
    }
    return radius * largest;
  }

  // The sim robot, armed, follows the controller; the world settles at its measured joints.
  // Open loop first (feedback off, nothing observed) until the robot has arrived: its joints
  // are where the loop starts, its true error the reference. Then at least `seconds`, and 30
  // frames judged, with feedback on and every frame through `lie`; every sample is judged.
  struct Outcome {
    double open_loop = NAN, bound = NAN, worst = 0, last = NAN;
    // The smallest margin open loop + bound − true error, and the largest joint distance (rad)
    // of the measured and the commanded joints from where the loop started, at any sample.
    double margin = INFINITY, measured_step = 0, commanded_step = 0;
    int samples = 0, arrived_samples = 0, blocked_samples = 0, unsolved_samples = 0;
    std::shared_ptr<const ControllerSnapshot> snapshot;
    LinkStatus link;
    OnlineCalibrationStatus calibration;
  };
  Outcome run(const Lie& lie, double seconds) {
    LinkConfig config;
    config.kind = LinkKind::Sim;
    config.sim_initial_joints = model.robot->reference_joints;
    auto link = make_robot_link(config, *model.robot->model, model.robot->collisions);
    link->start();
    Controller controller(model);
    SimulatedCamera camera;
    camera.marker_nodes = targets.nodes;
    SimulatedWorld world(test::different_world(model), model, camera, 10.0, 7);
    OnlineCalibration calibration(controller, model);
    controller.set_targets(targets);
    controller.start();
    const Clock::time_point start = Clock::now();
    const auto elapsed = [&] {
      return std::chrono::duration<double>(Clock::now() - start).count();
    };
    std::string why;
    while (!link->arm(&why) && elapsed() < 10)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_TRUE(link->status().armed) << why;

    Outcome out;
    std::uint64_t seen = 0;
    double hostile_since = -1;
    int frames = 0;
    const double radius = ControllerOptions{}.trust_region;
    Eigen::VectorXd start_joints;
    // A budget, not a speed test: with a 30 s online fit on the same two cores at load 16 the
    // controller judged 18 frames in 85 s (it takes only the newest while it iterates).
    while (elapsed() < 240) {
      const auto snap = controller.wait_for_snapshot(seen, 0.02);
      if (snap->sequence > seen) seen = snap->sequence, link->set_target(snap->joints, snap->safe);
      const LinkStatus st = link->status();
      if (st.measured.size() != snap->joints.size()) continue;
      std::optional<ObservationFrame> frame;
      bool solved = true;
      try {
        frame = world.step(elapsed(), st.measured);
      } catch (const NoEquilibrium&) {
        // The world's own Newton, not the loop: in a patch of joints about 1e-4 rad across,
        // 0.006 rad from this pose, it stalls at 7.66e-6 N whichever linear solver or step
        // (seen in 2 of ~25 runs; the world may be near a fold there). Its true error is then
        // unknown: the sample is counted, not judged, and no frame is taken.
        solved = false;
      }
      const double true_error = solved ? world.true_error(targets) : NAN;
      if (hostile_since < 0) {  // the open loop, until the robot stands at the optimizer's joints
        // Stopped for the targets: not the first snapshot's "idle" at the reference joints,
        // where the robot starts (that open loop is another, before the optimizer's walk).
        const bool stopped = snap->status == ControllerStatus::Reached ||
                             snap->status == ControllerStatus::BestEffort;
        if (st.arrived && stopped && solved) {
          out.open_loop = true_error;
          start_joints = snap->joints;  // the trust region's centre: where the optimizer stopped
          out.bound = bound(start_joints, world.positions(), radius);
          controller.set_feedback(true);
          hostile_since = elapsed();
        }
        continue;
      }
      if (solved) {
        out.worst = std::max(out.worst, true_error);
        out.margin = std::min(out.margin, out.open_loop + out.bound - true_error);
        out.last = true_error;
      } else {
        ++out.unsolved_samples;
      }
      out.measured_step =
          std::max(out.measured_step, (st.measured - start_joints).cwiseAbs().maxCoeff());
      out.commanded_step =
          std::max(out.commanded_step, (snap->joints - start_joints).cwiseAbs().maxCoeff());
      ++out.samples;
      if (st.blocked) ++out.blocked_samples;
      if (st.arrived) ++out.arrived_samples;
      if (frame) {
        lie(*frame, frames++);
        calibration.observe(*frame);
      }
      calibration.poll(elapsed());
      // Long enough, and enough frames judged: on a loaded machine the controller takes only
      // the newest of the frames that arrive while it iterates.
      const std::uint64_t judged = snap->gate.frames_checked + snap->observations_ignored;
      if (elapsed() - hostile_since > seconds && judged >= 30) break;
    }
    calibration.wait();
    out.snapshot = controller.snapshot();
    out.link = link->status();
    out.calibration = calibration.status();
    controller.stop();
    link->stop();
    EXPECT_TRUE(std::isfinite(out.open_loop)) << "the robot never arrived in the open loop";
    EXPECT_GE(out.snapshot->gate.frames_checked + out.snapshot->observations_ignored, 30u)
        << "too few frames judged to say anything (" << frames << " sent)";
    return out;
  }

  // What the gate, the authority and the trust region guarantee whatever the lie, at every
  // sample (in transit too): no correction beyond max_correction, no joint, commanded or
  // measured, farther than the trust region from where the loop started, the world's true
  // error within the open loop's plus the bound, and the user keeps the robot.
  static void expect_bounds_held(const Outcome& out) {
    EXPECT_LE(out.snapshot->authority.largest, FeedbackOptions{}.max_correction + 1e-12);
    const double radius = ControllerOptions{}.trust_region;
    EXPECT_LE(out.commanded_step, radius + 1e-9);
    EXPECT_LE(out.measured_step, radius + 1e-9);
    EXPECT_GE(out.margin, 0) << "true error up to " << out.worst * 1e3 << " mm, open loop "
                             << out.open_loop * 1e3 << " mm + bound " << out.bound * 1e3 << " mm";
    EXPECT_GT(out.samples, 100);
    EXPECT_LE(out.unsolved_samples, out.samples / 10) << "the world could not be judged";
    EXPECT_TRUE(out.link.armed) << out.link.reason;
  }
  static void print(const Outcome& out) {
    std::printf("link held short of a graze in %d samples, world unsolved in %d\n",
                out.blocked_samples, out.unsolved_samples);
    std::printf(
        "open loop %.1f mm + bound %.1f mm; worst %.1f mm (margin %.1f mm) over %d samples, %d "
        "arrived, last %.1f mm; joints from the loop's start: %.4f rad commanded, %.4f "
        "measured; gate: %llu/%llu markers, "
        "%llu/%llu frames rejected; largest correction %.1f mm; calibrations %llu run, "
        "%llu applied (%s)\n",
        out.open_loop * 1e3, out.bound * 1e3, out.worst * 1e3, out.margin * 1e3, out.samples,
        out.arrived_samples, out.last * 1e3, out.commanded_step, out.measured_step,
        (unsigned long long)out.snapshot->gate.markers_rejected,
        (unsigned long long)out.snapshot->gate.markers_checked,
        (unsigned long long)out.snapshot->gate.frames_rejected,
        (unsigned long long)out.snapshot->gate.frames_checked,
        out.snapshot->authority.largest * 1e3, (unsigned long long)out.calibration.runs,
        (unsigned long long)out.calibration.applied_runs, out.calibration.error.c_str());
  }

  const Scene model = load_scene(test::source_path("scenes/yumi_bar.json"));
  ShapeTargets targets;
  std::vector<Vec3> directions;  // per marker, unit
  std::mt19937 sizes{33};
};

TEST_F(HostileObservations, MarkersFiveToThreeHundredMillimetresOffAreGatedAndTheAuthorityHolds) {
  const Outcome out = run([&](ObservationFrame& f, int) { falsify(f, lie_size()); }, 5);
  expect_bounds_held(out), print(out);
  EXPECT_GT(out.snapshot->gate.frames_rejected, 0u);
  EXPECT_GT(out.snapshot->observations, 0u);  // the smaller lies pass the gate: the bound holds
}

// The worst a lie can do: consistent, and inside the gate (25 mm; the gate is 40 mm, though a
// marker whose lie adds to the model's own 17-20 mm error falls outside at first). The feedback
// takes it, and the authority bound is what stops it.
TEST_F(HostileObservations, ALieInsideTheGateMovesNoCorrectionBeyondTheBound) {
  const Outcome out = run([&](ObservationFrame& f, int) { falsify(f, 0.025); }, 5);
  expect_bounds_held(out), print(out);
  EXPECT_GT(out.snapshot->authority.largest, 0.015) << "the lie was taken";
}

TEST_F(HostileObservations, MarkersOneMetreOffAreAllRejectedAndMoveNothing) {
  const Outcome out = run([&](ObservationFrame& f, int) { falsify(f, 1.0); }, 4);
  expect_bounds_held(out), print(out);
  EXPECT_GT(out.snapshot->gate.frames_rejected, 20u);
  EXPECT_EQ(out.snapshot->gate.frames_rejected, out.snapshot->gate.frames_checked);
  EXPECT_EQ(out.snapshot->observations, 0u);
  EXPECT_EQ(out.snapshot->authority.largest, 0);  // not a millimetre of correction
  EXPECT_EQ(out.calibration.applied_runs, 0u) << "a calibration from lies was applied";
}

TEST_F(HostileObservations, AlternatingGoodAndLyingFramesAreGatedAndTheAuthorityHolds) {
  const Outcome out = run(
      [&](ObservationFrame& f, int count) {
        if (count % 2) falsify(f, lie_size());
      },
      5);
  expect_bounds_held(out), print(out);
  EXPECT_GT(out.snapshot->gate.frames_rejected, 0u);
  EXPECT_GT(out.snapshot->observations, 0u);  // the good frames are taken
}

}  // namespace
}  // namespace shapectl
