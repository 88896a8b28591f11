#pragma once
// EGM datagrams (proto/egm.proto) for one YuMi arm, both directions, with the 7th joint carried
// as the first external axis as the protocol does. Our side speaks radians in chain order
// (URDF 1, 2, 7, 3, 4, 5, 6); the wire speaks degrees in ABB order:
//   joints = deg(q0, q1, q3, q4, q5, q6), externalJoints = deg(q2).
// A codec reuses its protobuf messages and buffer: one per thread, no allocation when warm.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace shapectl {

using ArmJoints = Eigen::Matrix<double, 7, 1>;  // chain order, rad (or rad/s)

// EgmRobot: the controller's sample.
struct EgmFeedback {
  std::uint32_t seqno = 0;               // controller's counter
  std::uint32_t tm = 0;                  // controller's time stamp, ms
  ArmJoints joints = ArmJoints::Zero();  // measured (feedBack)
  bool motors_on = false;
  bool egm_running = false;    // mciState RUNNING
  bool rapid_running = false;  // rapidExecState RUNNING or UNDEFINED (an EGM quirk after restart)
  // Why the arm will not follow commands ("motors off", "EGM not running", ...); empty if it will.
  std::string_view fault() const;
};

// EgmSensor: our reply.
struct EgmCommand {
  std::uint32_t seqno = 0;                 // our counter, +1 per message
  std::uint32_t tm = 0;                    // our time stamp, ms
  ArmJoints joints = ArmJoints::Zero();    // planned position
  ArmJoints velocity = ArmJoints::Zero();  // speedRef (feed-forward), rad/s
};

class EgmCodec {
 public:
  // The controller's messages are far smaller (~100-450 bytes); anything above is refused.
  static constexpr std::size_t max_datagram = 1024;

  EgmCodec();
  ~EgmCodec();
  EgmCodec(const EgmCodec&) = delete;
  EgmCodec& operator=(const EgmCodec&) = delete;

  // Sensor side. False, with a short reason in `why` (static text), when the datagram is not a
  // well-formed EgmRobot DATA message with 6 finite, plausible joints and an external axis.
  bool decode_robot(std::string_view datagram, EgmFeedback& out, std::string_view* why);
  // The EgmSensor CORRECTION bytes, valid until the next encode; empty if any value is not
  // finite (never sent).
  std::string_view encode_sensor(const EgmCommand& command);

  // Controller side, for the simulator and tests.
  std::string_view encode_robot(const EgmFeedback& feedback);
  bool decode_sensor(std::string_view datagram, EgmCommand& out, std::string_view* why);

 private:
  struct Messages;
  std::unique_ptr<Messages> messages_;
  std::string buffer_;
};

}  // namespace shapectl
