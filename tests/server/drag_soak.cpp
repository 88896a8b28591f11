// Issue 32, item 5: dragging targets in the GUI must not disarm the simulated link. Two nodes'
// targets go round circles at 30 Hz through the Session the GUI uses, with the sim link armed;
// the link stays armed and no command it sends self-collides (its session log, read back).
// SHAPECTL_SOAK_SECONDS sets the duration (default 600); CTest test `drag_soak`, label `soak`.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <thread>

#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/command_log.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/server/session.hpp>

#include "support/controller_wait.hpp"
#include "support/test_support.hpp"

namespace shapectl::server {
namespace {

double soak_seconds() {
  const char* text = std::getenv("SHAPECTL_SOAK_SECONDS");
  return text ? std::atof(text) : 600;
}

// The node nearest `point` among `positions` (3n).
int nearest_node(const Positions& positions, const Vec3& point) {
  int best = 0;
  for (int i = 1; i < positions.size() / 3; ++i)
    if ((positions.segment<3>(3 * i) - point).norm() <
        (positions.segment<3>(3 * best) - point).norm())
      best = i;
  return best;
}

struct CommandStats {
  std::uint64_t commands = 0;
  double min_clearance = std::numeric_limits<double>::infinity();
  std::uint64_t within_margin = 0;  // commands closer than the spheres' margin (barrier zone)
  CommandLogCheck limits;           // the worst ratios and violations over all chunks
};

// Reads the log line by line (it is large): every command's clearance, and the velocity and
// acceleration check of command_log on chunks (each after the "link" event; the first two
// commands of a chunk lack their history).
CommandStats command_stats(const std::filesystem::path& file, const RobotModel& robot,
                           const CollisionModel& spheres) {
  CommandStats stats;
  std::ifstream in(file);
  std::string line;
  std::vector<LoggedEvent> chunk;
  LoggedEvent link_event;
  auto check_chunk = [&] {
    if (chunk.empty()) return;
    chunk.insert(chunk.begin(), link_event);
    const CommandLogCheck c = check_command_log(chunk, file.string());
    stats.limits.velocity_ratio = std::max(stats.limits.velocity_ratio, c.velocity_ratio);
    stats.limits.acceleration_ratio =
        std::max(stats.limits.acceleration_ratio, c.acceleration_ratio);
    stats.limits.violations.insert(stats.limits.violations.end(), c.violations.begin(),
                                   c.violations.end());
    chunk.clear();
  };
  for (int number = 1; std::getline(in, line); ++number) {
    LoggedEvent e{number, 0, "", nlohmann::json::parse(line, nullptr, false)};
    if (!e.fields.is_object()) continue;  // a cut last line
    e.t = e.fields["t"].get<double>();
    e.event = e.fields["event"].get<std::string>();
    if (e.event == "link") link_event = e;
    if (e.event != "command") continue;
    const Eigen::VectorXd q = vector_from_json(e.fields["joints"]);
    const double clearance = spheres.min_clearance(forward_kinematics(robot, q));
    ++stats.commands;
    stats.min_clearance = std::min(stats.min_clearance, clearance);
    stats.within_margin += clearance < spheres.margin();
    chunk.push_back(std::move(e));
    if (chunk.size() == 20000) check_chunk();
  }
  check_chunk();
  return stats;
}

TEST(DragSoak, SimLinkStaysArmedAndNeverCommandsACollision) {
  const double duration = soak_seconds();
  test::TempDir dir;
  const auto log_file = dir.path() / "link.jsonl";
  const auto scene_file = test::source_path("scenes/yumi_bar.json");
  const Scene scene = load_scene(scene_file);
  ASSERT_TRUE(scene.robot->collisions);
  // One file however long the soak runs: every command it sent is checked, none rotated away.
  auto log = std::make_shared<SessionLog>(log_file, SessionLogLimits{.max_bytes = 8ull << 30});
  LinkConfig config;  // as `serve --robot sim`: defaults, starting at the reference joints
  config.sim_initial_joints = scene.robot->reference_joints;
  const auto link = make_robot_link(config, *scene.robot->model, scene.robot->collisions, log);
  link->start();
  Session session(scene_file, {}, link.get());

  // Two nodes a third of the way in from each end of the bar (along y), each dragged round a
  // 9 cm circle in its vertical plane about a point pulled 9 cm towards the other node, at
  // different speeds: the arms come within the spheres' margin and their relation keeps
  // changing (before the look-ahead this disarmed within 30 s: "commanded pose: self-collision
  // (spheres overlap by 0.006 mm)").
  const auto rest = session.controller().snapshot()->positions;
  const Vec3 centre(0.39047, 0, 0.25527);
  const int nodes[2] = {nearest_node(rest, centre + Vec3(0, -0.06, 0)),
                        nearest_node(rest, centre + Vec3(0, 0.06, 0))};
  const double inward[2] = {0.09, -0.09};  // m along y, towards the other node
  const double periods[2] = {7.0, -5.0};   // s, the second turning the other way
  auto drag = [&](double t) {
    for (int k = 0; k < 2; ++k) {
      const double phase = 2 * M_PI * t / periods[k];
      const Vec3 p = rest.segment<3>(3 * nodes[k]) + Vec3(0, inward[k], 0) +
                     0.09 * Vec3(std::cos(phase), 0, std::sin(phase));
      const auto reply = session.handle(nlohmann::json{{"type", "set_target"},
                                                       {"node", nodes[k]},
                                                       {"position", {p.x(), p.y(), p.z()}}}
                                            .dump());
      ASSERT_TRUE(reply.ok) << reply.text;
    }
  };

  for (int i = 0; i < 5000 && !link->status().connected; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const auto armed = session.handle(R"({"type":"arm"})");
  ASSERT_TRUE(armed.ok) << armed.text;
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  std::uint64_t ticks = 0, holding = 0;
  double target_clearance = std::numeric_limits<double>::infinity();  // the optimizer's poses
  std::string disarmed;
  while (disarmed.empty()) {
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t >= duration) break;
    drag(t);
    session.tick();
    const LinkStatus st = link->status();
    if (!st.armed) disarmed = st.reason + " (after " + std::to_string(t) + " s)";
    holding += !st.reason.empty();
    target_clearance = std::min(target_clearance, session.snapshot()->min_clearance);
    ++ticks;
    next += std::chrono::microseconds(33333);
    std::this_thread::sleep_until(next);
  }
  link->disarm("soak over");
  link->stop();
  const std::uint64_t sent = link->status().commands_sent;
  log.reset();

  const CommandStats stats = command_stats(log_file, *scene.robot->model, *scene.robot->collisions);
  std::cout << "drag soak: " << duration << " s, " << ticks << " target updates, " << sent
            << " commands sent (" << stats.commands << " logged), min clearance "
            << stats.min_clearance * 1000 << " mm, " << stats.within_margin
            << " within the spheres' margin of " << scene.robot->collisions->margin() * 1000
            << " mm (the optimizer's poses: min " << target_clearance * 1000 << " mm), holding at "
            << holding << " updates, velocity ratio " << stats.limits.velocity_ratio
            << ", acceleration ratio " << stats.limits.acceleration_ratio << "\n";
  EXPECT_EQ(disarmed, "");
  EXPECT_GT(ticks, duration * 30 * 0.5);  // the drag really ran at (about) 30 Hz
  EXPECT_GT(stats.commands, duration * 250 * 0.5);
  EXPECT_GE(stats.min_clearance, 0);
  EXPECT_TRUE(stats.limits.ok()) << stats.limits.violations.front();
}

}  // namespace
}  // namespace shapectl::server
