#pragma once
// Shared by the link tests: the YuMi model with its 14 arm joints active, and waiting.
#include <chrono>
#include <functional>
#include <thread>

#include <shapectl/robot/robot_model.hpp>

#include "support/test_support.hpp"
#include "support/wait_bound.hpp"

namespace shapectl::test {

inline RobotModel yumi_arms() {
  RobotModel robot = RobotModel::load_urdf_file(source_path("data/robots/yumi/yumi.urdf"));
  std::vector<std::string> names;
  for (const char* arm : {"l", "r"})
    for (int axis : {1, 2, 7, 3, 4, 5, 6})
      names.push_back("yumi_joint_" + std::to_string(axis) + "_" + arm);
  robot.set_active_joints(names);
  return robot;
}

// Polls `done` every 2 ms; false if it did not become true within wait_bound(seconds).
inline bool wait_until(const std::function<bool()>& done, double seconds) {
  const auto end =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_bound(seconds));
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

inline void sleep_seconds(double s) {
  std::this_thread::sleep_for(std::chrono::duration<double>(s));
}

}  // namespace shapectl::test
