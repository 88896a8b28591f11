#pragma once
// The WebSocket protocol of `shapectl serve` (reference: docs/gui.md). Clients send JSON text
// commands; the server answers each with {"type":"ok"} or {"type":"error"}, and streams
// JSON "state" messages plus binary node-position frames to every client.
//
// Parsing is strict: unknown types or keys, wrong types, non-finite or out-of-range numbers,
// unknown node ids and oversized arrays are all InputError ("message: targets[2].node: expected
// an integer in [0, 1535], got 9000"), so nothing invalid ever reaches the controller.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <shapectl/calib/observations.hpp>
#include <shapectl/control/controller.hpp>

namespace shapectl::server {

inline constexpr int protocol_version = 1;
// Largest text message accepted; larger ones close the connection (WebSocket code 1009).
inline constexpr std::size_t max_message_bytes = 1 << 20;
inline constexpr int max_json_depth = 16;
inline constexpr std::size_t max_centerline_points = 2000;
// Targets and centre-line points must lie within this distance of the world origin (m).
inline constexpr double max_coordinate = 10.0;
// A sketched centre-line shorter than this (m, summed over its segments) is degenerate: the
// targets built from it would have no direction.
inline constexpr double min_centerline_length = 1e-3;

// What a command may refer to in the current scene.
struct ProtocolContext {
  int node_count = 0;
  std::vector<std::string> joint_names;
  Eigen::VectorXd lower_limits, upper_limits;
  std::vector<std::string> scene_names;
  const RobotModel* robot = nullptr;  // observe: the frame's joints by name
};

struct Command {
  enum class Type {
    Ping,
    SetTarget,
    RemoveTarget,
    SetTargets,
    ClearTargets,
    SetCenterline,
    SetPaused,
    SetJoint,
    SetJoints,
    Reset,
    LoadScene,
    Arm,
    Disarm,
    Observe,
    SetFeedback,
    Calibrate,
    SetAutoCalibration
  };
  Type type = Type::Ping;
  nlohmann::json id;             // echoed in the reply; null when the client sent none
  int node = -1;                 // SetTarget, RemoveTarget
  Vec3 position = Vec3::Zero();  // SetTarget, world frame, m
  ShapeTargets targets;          // SetTargets
  std::vector<Vec3> points;      // SetCenterline, world frame, m
  bool paused = false;           // SetPaused
  int joint = -1;                // SetJoint: index into the active joints
  double value = 0;              // SetJoint, rad (m for prismatic joints)
  Eigen::VectorXd joints;        // SetJoints
  std::string scene;             // LoadScene: one of ProtocolContext::scene_names
  ObservationFrame frame;        // Observe: markers and/or points, the joints they were taken at
  bool on = false;               // SetFeedback, SetAutoCalibration
};

// The client's "id" if `text` is an object carrying a valid one (integer or string of at most
// 64 characters), else null; used to address an error reply to a message that failed to parse.
nlohmann::json message_id(std::string_view text);
// Whether `text` is an object of type "observe", whatever else is wrong with it: a rejected
// observation is counted as one.
bool is_observe_message(std::string_view text);

// Parses and validates one text message; throws InputError (source "message") when invalid.
Command parse_command(std::string_view text, const ProtocolContext& context);

std::string ok_reply(const nlohmann::json& id);
std::string error_reply(const nlohmann::json& id, const std::string& message);

// Binary frame with node positions:
//   bytes 0–3 "POS1", 4–7 node count n (uint32), 8–15 snapshot sequence (float64),
//   then 3n float32 [x0 y0 z0 x1 ...] in the world frame, metres; all little-endian.
std::string positions_frame(const ControllerSnapshot& snapshot);

// Poses in messages are 16 numbers, column-major: message_pose_json (io/json_eigen.hpp).

}  // namespace shapectl::server
