#include "bench_closed_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/online_calibration.hpp>
#include <shapectl/calib/simulated_world.hpp>
#include <shapectl/link/make_robot_link.hpp>

namespace shapectl::cli {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double give_up_after = 30;  // s

Scene world_of(const Scene& model) {
  Scene world = model;
  world.material =
      material_from_youngs(1.5 * youngs_modulus_of(model.material),
                           poisson_ratio_of(model.material), 0.8 * model.material.density);
  const Vec3 shifts[2] = {Vec3(0, 1, -1).normalized(), Vec3(1, 0, 1).normalized()};
  for (std::size_t k = 0; k < world.grips.size(); ++k)
    world.grips[k].offset = Eigen::Translation3d(0.004 * shifts[k % 2]) *
                            Eigen::AngleAxisd(3 * M_PI / 180, Vec3::UnitZ());
  return world;
}

// Seconds until the world's true error first fell below 1 mm (NaN if not within
// give_up_after), running the controller, the sim robot, the world and its camera.
double time_to_1mm(const Scene& model, const Scene& world_scene, const ShapeTargets& targets,
                   bool calibrate, unsigned seed) {
  SimulatedCamera camera;
  camera.marker_nodes = targets.nodes;
  SimulatedWorld world(world_scene, model, camera, 10, seed);
  LinkConfig config;
  config.sim_initial_joints = model.robot->reference_joints;
  const auto link = make_robot_link(config, *model.robot->model, model.robot->collisions);
  Controller controller(model);
  OnlineCalibration calibration(controller, model, {.automatic = calibrate});
  controller.set_targets(targets);
  controller.set_feedback(true);
  controller.start();
  link->start();
  const Clock::time_point start = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  std::string why;
  while (!link->arm(&why) && elapsed() < 5)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  double reached = NAN;
  std::uint64_t seen = 0;
  while (elapsed() < give_up_after) {
    const auto snap = controller.wait_for_snapshot(seen, 0.02);
    if (snap->sequence > seen) seen = snap->sequence, link->set_target(snap->joints, snap->safe);
    const LinkStatus st = link->status();
    if (st.measured.size() != snap->joints.size()) continue;
    if (auto frame = world.step(elapsed(), st.measured)) calibration.observe(*frame);
    calibration.poll(elapsed());
    if (world.true_error(targets) < 1e-3) {
      reached = elapsed();
      break;
    }
  }
  link->disarm("bench finished");
  controller.stop();
  link->stop();
  return reached;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

}  // namespace

void bench_closed_loop(const Scene& scene, int trials, unsigned seed, nlohmann::json& record) {
  if (!scene.robot || scene.grips.empty() || scene.robot->reference_joints.size() < 8) return;
  Eigen::VectorXd goal = scene.robot->reference_joints;
  goal[0] -= 0.03, goal[7] += 0.03;
  const ObjectState arch = equilibrium_along_path(GrippedObject(scene), goal);
  ShapeTargets targets;
  for (int node = 0; node < scene.object_mesh->node_count(); node += 37)
    targets.nodes.push_back(node),
        targets.positions.push_back(arch.positions().segment<3>(3 * node));
  const Scene world = world_of(scene);
  for (const bool calibrate : {false, true}) {
    std::vector<double> times;
    int missed = 0;
    for (int trial = 0; trial < trials; ++trial) {
      const double t = time_to_1mm(scene, world, targets, calibrate, seed + trial);
      if (std::isnan(t)) ++missed;
      else times.push_back(t);
    }
    std::printf(
        "  closed loop, world 1.5x stiffer, 0.8x dense, grips 4 mm / 3 deg off, %s: true error "
        "< 1 mm after %.1f s (median of %d; max %.1f s; %d not within %.0f s)\n",
        calibrate ? "feedback + online calibration" : "feedback only", median(times),
        static_cast<int>(times.size()),
        times.empty() ? NAN : *std::max_element(times.begin(), times.end()), missed, give_up_after);
    record[calibrate ? "feedback_calibration" : "feedback"] = {
        {"median_s", median(times)},
        {"max_s", times.empty() ? NAN : *std::max_element(times.begin(), times.end())},
        {"reached", times.size()},
        {"trials", trials}};
  }
}

}  // namespace shapectl::cli
