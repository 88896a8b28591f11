#include <shapectl/link/egm_codec.hpp>

#include <cmath>
#include <numbers>

#include "egm.pb.h"

namespace shapectl {

namespace egm = abb::egm;

namespace {

constexpr double deg_per_rad = 180.0 / std::numbers::pi;
// No YuMi axis goes beyond ±290° or 400°/s; a larger finite value is garbage.
constexpr double plausible_deg = 360.0;
constexpr double plausible_deg_per_s = 1000.0;

// Chain index of each ABB robot axis 1..6 (joints[0..5]); axis 7 is chain index 2.
constexpr int chain_of_robot_axis[6] = {0, 1, 3, 4, 5, 6};
constexpr int chain_of_axis7 = 2;

void put_joints(const ArmJoints& q, egm::EgmJoints* joints, egm::EgmJoints* external) {
  joints->clear_joints();
  for (int axis = 0; axis < 6; ++axis)
    joints->add_joints(q[chain_of_robot_axis[axis]] * deg_per_rad);
  external->clear_joints();
  external->add_joints(q[chain_of_axis7] * deg_per_rad);
}

// False with `why` unless 6 robot values and ≥ 1 external value, all finite and plausible.
bool get_joints(const egm::EgmJoints& joints, const egm::EgmJoints& external, ArmJoints& q,
                std::string_view* why, double plausible = plausible_deg) {
  if (joints.joints_size() != 6) return *why = "not 6 robot joints", false;
  if (external.joints_size() < 1) return *why = "no external axis (joint 7)", false;
  for (int axis = 0; axis < 6; ++axis) q[chain_of_robot_axis[axis]] = joints.joints(axis);
  q[chain_of_axis7] = external.joints(0);
  if (!q.allFinite()) return *why = "joint value not finite", false;
  if (q.cwiseAbs().maxCoeff() > plausible) return *why = "joint value implausibly large", false;
  q /= deg_per_rad;
  return true;
}

}  // namespace

std::string_view EgmFeedback::fault() const {
  if (!motors_on) return "motors off";
  if (!egm_running) return "EGM not running";
  if (!rapid_running) return "RAPID stopped";
  return {};
}

struct EgmCodec::Messages {
  egm::EgmRobot robot;
  egm::EgmSensor sensor;
};

EgmCodec::EgmCodec() : messages_(std::make_unique<Messages>()) { buffer_.reserve(max_datagram); }
EgmCodec::~EgmCodec() = default;

bool EgmCodec::decode_robot(std::string_view datagram, EgmFeedback& out, std::string_view* why) {
  std::string_view ignored;
  if (!why) why = &ignored;
  if (datagram.size() > max_datagram) return *why = "oversized", false;
  egm::EgmRobot& m = messages_->robot;
  // Partial parse + IsInitialized: the same check as ParseFromArray, without protobuf's
  // stderr message for every bad datagram.
  if (!m.ParsePartialFromArray(datagram.data(), static_cast<int>(datagram.size())) ||
      !m.IsInitialized())
    return *why = "not an EgmRobot message", false;
  if (m.header().mtype() != egm::EgmHeader::MSGTYPE_DATA) return *why = "not a DATA message", false;
  if (!m.has_feedback()) return *why = "no feedBack", false;
  if (!get_joints(m.feedback().joints(), m.feedback().externaljoints(), out.joints, why))
    return false;
  out.seqno = m.header().seqno();
  out.tm = m.header().tm();
  out.motors_on = m.has_motorstate() && m.motorstate().state() == egm::EgmMotorState::MOTORS_ON;
  out.egm_running = m.has_mcistate() && m.mcistate().state() == egm::EgmMCIState::MCI_RUNNING;
  out.rapid_running = m.has_rapidexecstate() &&
                      (m.rapidexecstate().state() == egm::EgmRapidCtrlExecState::RAPID_RUNNING ||
                       m.rapidexecstate().state() == egm::EgmRapidCtrlExecState::RAPID_UNDEFINED);
  return true;
}

std::string_view EgmCodec::encode_sensor(const EgmCommand& command) {
  if (!command.joints.allFinite() || !command.velocity.allFinite()) return {};
  egm::EgmSensor& m = messages_->sensor;
  m.Clear();
  auto* header = m.mutable_header();
  header->set_seqno(command.seqno);
  header->set_tm(command.tm);
  header->set_mtype(egm::EgmHeader::MSGTYPE_CORRECTION);
  put_joints(command.joints, m.mutable_planned()->mutable_joints(),
             m.mutable_planned()->mutable_externaljoints());
  put_joints(command.velocity, m.mutable_speedref()->mutable_joints(),
             m.mutable_speedref()->mutable_externaljoints());
  buffer_.clear();
  m.AppendToString(&buffer_);
  return buffer_;
}

std::string_view EgmCodec::encode_robot(const EgmFeedback& feedback) {
  egm::EgmRobot& m = messages_->robot;
  m.Clear();
  auto* header = m.mutable_header();
  header->set_seqno(feedback.seqno);
  header->set_tm(feedback.tm);
  header->set_mtype(egm::EgmHeader::MSGTYPE_DATA);
  put_joints(feedback.joints, m.mutable_feedback()->mutable_joints(),
             m.mutable_feedback()->mutable_externaljoints());
  m.mutable_motorstate()->set_state(feedback.motors_on ? egm::EgmMotorState::MOTORS_ON
                                                       : egm::EgmMotorState::MOTORS_OFF);
  m.mutable_mcistate()->set_state(feedback.egm_running ? egm::EgmMCIState::MCI_RUNNING
                                                       : egm::EgmMCIState::MCI_STOPPED);
  m.mutable_rapidexecstate()->set_state(feedback.rapid_running
                                            ? egm::EgmRapidCtrlExecState::RAPID_RUNNING
                                            : egm::EgmRapidCtrlExecState::RAPID_STOPPED);
  buffer_.clear();
  m.AppendToString(&buffer_);
  return buffer_;
}

bool EgmCodec::decode_sensor(std::string_view datagram, EgmCommand& out, std::string_view* why) {
  std::string_view ignored;
  if (!why) why = &ignored;
  if (datagram.size() > max_datagram) return *why = "oversized", false;
  egm::EgmSensor& m = messages_->sensor;
  if (!m.ParsePartialFromArray(datagram.data(), static_cast<int>(datagram.size())) ||
      !m.IsInitialized())
    return *why = "not an EgmSensor message", false;
  if (m.header().mtype() != egm::EgmHeader::MSGTYPE_CORRECTION)
    return *why = "not a CORRECTION message", false;
  if (!m.has_planned()) return *why = "no planned", false;
  if (!get_joints(m.planned().joints(), m.planned().externaljoints(), out.joints, why))
    return false;
  out.velocity.setZero();
  if (m.has_speedref() && !get_joints(m.speedref().joints(), m.speedref().externaljoints(),
                                      out.velocity, why, plausible_deg_per_s))
    return false;
  out.seqno = m.header().seqno();
  out.tm = m.header().tm();
  return true;
}

}  // namespace shapectl
