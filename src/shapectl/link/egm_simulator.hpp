#pragma once
// A stand-in for the YuMi controller's side of EGM, to try the whole chain without hardware:
// every `period` each arm sends an EgmRobot (measured joints, motors on, EGM running) from its
// own UDP socket to the sensor's port and moves its simulated arm towards the newest EgmSensor
// command received, within YuMi's joint speeds and `acceleration`. It also checks the commands
// it uses, one per cycle (speed and acceleration implied by consecutive cycles' commands, over
// runs of cycles that each brought a new command), and every command against the joint limits.
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <shapectl/link/egm_codec.hpp>
#include <shapectl/link/sim_robot.hpp>
#include <shapectl/link/udp_socket.hpp>

namespace shapectl {

// YuMi arm limits in chain order (URDF = ABB spec, reference/yumi/kinematics.md §5).
GovernorLimits yumi_arm_limits(double acceleration);

struct EgmSimulatorConfig {
  std::string sensor_address = "127.0.0.1";    // where the link listens
  int left_port = 6511;                        // 0: no left arm
  int right_port = 6512;                       // 0: no right arm
  double period = 0.004;                       // s between feedback messages (250 Hz)
  ArmJoints left_initial = ArmJoints::Zero();  // chain order, rad
  ArmJoints right_initial = ArmJoints::Zero();
  double acceleration = 10;  // rad/s², the simulated arms' own limit
};

struct EgmSimArmStats {
  bool present = false;
  std::uint64_t feedback_sent = 0;
  std::uint64_t commands = 0;                  // valid EgmSensor replies received
  std::uint64_t rejected = 0;                  // replies that were not valid EgmSensor messages
  ArmJoints position = ArmJoints::Zero();      // the simulated arm, rad
  ArmJoints last_command = ArmJoints::Zero();  // rad
  // From consecutive cycles' commands (period apart), over all joints; restarted after a
  // pause, a cycle without a new command, or a late tick of the simulator's own.
  double max_speed = 0;              // rad/s
  double max_acceleration = 0;       // rad/s²
  std::uint64_t outside_limits = 0;  // commands outside the arm's joint limits
};

class EgmSimulator {
 public:
  explicit EgmSimulator(EgmSimulatorConfig config);  // InputError for a bad address
  ~EgmSimulator();

  void start();
  void stop();
  // Paused: no feedback is sent (a pulled cable); the arms finish their last command and hold.
  void set_paused(bool paused);
  EgmSimArmStats stats(int arm) const;  // 0 left, 1 right

 private:
  struct Arm;
  void run(std::stop_token stop);
  // `tick_time`: the tick's exact time (s, CLOCK_REALTIME, as kernel receive times).
  void tick(Arm& arm, bool paused, bool late, double tick_time);

  EgmSimulatorConfig config_;
  std::vector<std::unique_ptr<Arm>> arms_;  // [left, right]
  EgmCodec codec_;                          // simulator thread only
  std::atomic<bool> paused_{false};
  mutable std::mutex mutex_;  // guards the arms' stats and robots
  std::jthread thread_;
};

}  // namespace shapectl
