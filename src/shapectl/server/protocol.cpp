#include <shapectl/server/protocol.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <set>
#include <sstream>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_input.hpp>

namespace shapectl::server {

namespace {

const char* const source = "message";

// Size and nesting are checked before any parser runs (no valid command nests deeper than 4).
nlohmann::json parse_json(std::string_view text) {
  if (text.size() > max_message_bytes)
    throw InputError(source, "", "longer than " + std::to_string(max_message_bytes) + " bytes");
  if (json_too_deep_at(text, max_json_depth) != std::string_view::npos)
    throw InputError(source, "", "JSON nested deeper than " + std::to_string(max_json_depth));
  // Strictly: a key given twice is an error naming it, never silently the last one.
  try {
    return parse_json_text(text, source,
                           {.max_bytes = max_message_bytes, .max_depth = max_json_depth});
  } catch (const InputError&) {
    if (!nlohmann::json::accept(text.begin(), text.end()))
      throw InputError(source, "", "not valid JSON");
    throw;  // valid JSON with a key given twice
  }
}

bool valid_id(const nlohmann::json& id) {
  if (id.is_number_integer()) return true;
  return id.is_string() && id.get_ref<const std::string&>().size() <= 64;
}

Vec3 read_point(const JsonInput& j) {
  const Vec3 p = j.vec3();
  if (p.norm() > max_coordinate)
    j.fail("a point within " + std::to_string(static_cast<int>(max_coordinate)) +
           " m of the origin");
  return p;
}

int read_node(const JsonInput& j, const ProtocolContext& context) {
  if (context.node_count <= 0) j.fail_problem("the scene has no nodes");
  return static_cast<int>(j.integer_in(0, context.node_count - 1));
}

double read_joint_value(const JsonInput& j, const ProtocolContext& context, int joint) {
  const double v = j.number();
  const double lo = context.lower_limits[joint], hi = context.upper_limits[joint];
  if (v < lo - 1e-9 || v > hi + 1e-9)
    j.fail("a value within the limits of joint '" + context.joint_names[joint] + "' [" +
           std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

int read_joint(const JsonInput& j, const ProtocolContext& context) {
  const int count = static_cast<int>(context.joint_names.size());
  if (count == 0) j.fail_problem("the scene has no robot joints");
  if (j.is_string()) {
    const std::string name = j.string();
    for (int k = 0; k < count; ++k)
      if (context.joint_names[k] == name) return k;
    j.fail("the name of an active joint");
  }
  return static_cast<int>(j.integer_in(0, count - 1));
}

const std::vector<std::pair<std::string, Command::Type>>& type_names() {
  static const std::vector<std::pair<std::string, Command::Type>> names = {
      {"ping", Command::Type::Ping},
      {"set_target", Command::Type::SetTarget},
      {"remove_target", Command::Type::RemoveTarget},
      {"set_targets", Command::Type::SetTargets},
      {"clear_targets", Command::Type::ClearTargets},
      {"set_centerline", Command::Type::SetCenterline},
      {"set_paused", Command::Type::SetPaused},
      {"set_joint", Command::Type::SetJoint},
      {"set_joints", Command::Type::SetJoints},
      {"reset", Command::Type::Reset},
      {"load_scene", Command::Type::LoadScene},
      {"arm", Command::Type::Arm},
      {"disarm", Command::Type::Disarm},
      {"observe", Command::Type::Observe},
      {"set_feedback", Command::Type::SetFeedback},
      {"calibrate", Command::Type::Calibrate},
      {"set_auto_calibration", Command::Type::SetAutoCalibration},
  };
  return names;
}

// "id", if given: an integer or a short string, echoed in the reply.
nlohmann::json read_id(const JsonInput& message) {
  if (!message.has("id")) return nullptr;
  const nlohmann::json id = message.at("id").raw();
  if (!valid_id(id)) message.at("id").fail("an integer or a string of at most 64 characters");
  return id;
}

Command::Type read_type(const JsonInput& type) {
  const std::string name = type.string();
  const auto& names = type_names();
  const auto found = std::find_if(names.begin(), names.end(),
                                  [&](const auto& entry) { return entry.first == name; });
  if (found == names.end()) {
    std::string known;
    for (const auto& entry : names) known += (known.empty() ? "" : ", ") + entry.first;
    type.fail("one of " + known);
  }
  return found->second;
}

// set_targets: at most one target per node of the scene, each a node and a point.
ShapeTargets read_target_list(const JsonInput& list, const ProtocolContext& context) {
  if (list.size() > static_cast<std::size_t>(context.node_count))
    list.fail("at most one target per node (" + std::to_string(context.node_count) + ")");
  ShapeTargets targets;
  std::set<int> seen;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonInput t = list.at(k);
    t.expect_only({"node", "position"});
    const int node = read_node(t.at("node"), context);
    if (!seen.insert(node).second) t.at("node").fail("a node not targeted twice");
    targets.nodes.push_back(node);
    targets.positions.push_back(read_point(t.at("position")));
  }
  return targets;
}

// set_centerline: 2 to max_centerline_points points, at least 1 mm long in all.
std::vector<Vec3> read_centerline_points(const JsonInput& list) {
  if (list.size() < 2 || list.size() > max_centerline_points)
    list.fail("from 2 to " + std::to_string(max_centerline_points) + " points");
  std::vector<Vec3> points;
  double length = 0;
  for (std::size_t k = 0; k < list.size(); ++k) {
    points.push_back(read_point(list.at(k)));
    if (k > 0) length += (points[k] - points[k - 1]).norm();
  }
  if (!(length >= min_centerline_length)) {
    std::ostringstream arc;
    arc << std::setprecision(3) << length;
    list.fail("a centre-line at least 1 mm long (its arc length is " + arc.str() + " m)");
  }
  return points;
}

// set_joints: one value per active joint, each within its limits.
Eigen::VectorXd read_joint_list(const JsonInput& list, const ProtocolContext& context) {
  const std::size_t count = context.joint_names.size();
  if (count == 0) list.fail_problem("the scene has no robot joints");
  if (list.size() != count) list.fail("an array of " + std::to_string(count) + " joint values");
  Eigen::VectorXd joints(static_cast<Eigen::Index>(count));
  for (std::size_t k = 0; k < count; ++k)
    joints[static_cast<Eigen::Index>(k)] =
        read_joint_value(list.at(k), context, static_cast<int>(k));
  return joints;
}

// load_scene: one of the bundled scenes, by name.
std::string read_scene_name(const JsonInput& scene, const ProtocolContext& context) {
  const std::string name = scene.string();
  const auto& known = context.scene_names;
  if (std::find(known.begin(), known.end(), name) == known.end()) {
    std::string list;
    for (const auto& s : known) list += (list.empty() ? "" : ", ") + s;
    scene.fail("one of the bundled scenes: " + list);
  }
  return name;
}

// observe: one frame of OBSERVATIONS.json (calib/observations.hpp), never a points file (a
// client must not make the server read its files). Its markers feed the model-error feedback;
// the whole frame, points too, feeds the session's calibration.
ObservationFrame read_observation(const JsonInput& frame, const ProtocolContext& context) {
  if (!context.robot) frame.fail_problem("the scene has no robot: nothing to close the loop with");
  return read_observation_frame(frame, {.node_count = context.node_count,
                                        .robot = context.robot,
                                        .allow_points_files = false});
}

// The keys a command of this type may have, each read and checked into `c`.
void read_arguments(const JsonInput& message, const ProtocolContext& context, Command& c) {
  using T = Command::Type;
  switch (c.type) {
    case T::Ping:
    case T::ClearTargets:
    case T::Reset:
    case T::Calibrate:
    case T::Arm:
    case T::Disarm: message.expect_only({"type", "id"}); break;
    case T::SetTarget:
      message.expect_only({"type", "id", "node", "position"});
      c.node = read_node(message.at("node"), context);
      c.position = read_point(message.at("position"));
      break;
    case T::RemoveTarget:
      message.expect_only({"type", "id", "node"});
      c.node = read_node(message.at("node"), context);
      break;
    case T::SetTargets:
      message.expect_only({"type", "id", "targets"});
      c.targets = read_target_list(message.at("targets"), context);
      break;
    case T::SetCenterline:
      message.expect_only({"type", "id", "points"});
      c.points = read_centerline_points(message.at("points"));
      break;
    case T::SetPaused:
      message.expect_only({"type", "id", "paused"});
      c.paused = message.at("paused").boolean();
      break;
    case T::SetJoint:
      message.expect_only({"type", "id", "joint", "value"});
      c.joint = read_joint(message.at("joint"), context);
      c.value = read_joint_value(message.at("value"), context, c.joint);
      break;
    case T::SetJoints:
      message.expect_only({"type", "id", "joints"});
      c.joints = read_joint_list(message.at("joints"), context);
      break;
    case T::LoadScene:
      message.expect_only({"type", "id", "scene"});
      c.scene = read_scene_name(message.at("scene"), context);
      break;
    case T::Observe:
      message.expect_only({"type", "id", "frame"});
      c.frame = read_observation(message.at("frame"), context);
      break;
    case T::SetFeedback:
    case T::SetAutoCalibration:
      message.expect_only({"type", "id", "on"});
      c.on = message.at("on").boolean();
      break;
  }
}

}  // namespace

namespace {
// `text` parsed when it is within the size and nesting limits, else null (so is bad JSON).
nlohmann::json parsed_message(std::string_view text) {
  if (text.size() > max_message_bytes ||
      json_too_deep_at(text, max_json_depth) != std::string_view::npos)
    return nullptr;
  return nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
}
}  // namespace

nlohmann::json message_id(std::string_view text) {
  const nlohmann::json j = parsed_message(text);
  if (!j.is_object()) return nullptr;
  const auto it = j.find("id");
  if (it == j.end() || !valid_id(*it)) return nullptr;
  return *it;
}

bool is_observe_message(std::string_view text) {
  const nlohmann::json j = parsed_message(text);
  return j.is_object() && j.contains("type") && j["type"] == "observe";
}

Command parse_command(std::string_view text, const ProtocolContext& context) {
  const JsonInput message(parse_json(text), source);
  if (!message.is_object()) message.fail("a JSON object");
  Command c;
  c.id = read_id(message);
  c.type = read_type(message.at("type"));
  read_arguments(message, context, c);
  return c;
}

std::string ok_reply(const nlohmann::json& id) {
  return nlohmann::json{{"type", "ok"}, {"id", id}}.dump();
}

std::string error_reply(const nlohmann::json& id, const std::string& message) {
  // Replace invalid UTF-8 (echoed client bytes) instead of throwing.
  return nlohmann::json{{"type", "error"}, {"id", id}, {"message", message}}.dump(
      -1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string positions_frame(const ControllerSnapshot& snapshot) {
  static_assert(std::endian::native == std::endian::little, "frames are little-endian");
  const auto n = static_cast<std::uint32_t>(snapshot.positions.size() / 3);
  const double sequence = static_cast<double>(snapshot.sequence);
  std::string frame(16 + 12 * static_cast<std::size_t>(n), '\0');
  std::memcpy(frame.data(), "POS1", 4);
  std::memcpy(frame.data() + 4, &n, 4);
  std::memcpy(frame.data() + 8, &sequence, 8);
  for (std::size_t i = 0; i < 3 * static_cast<std::size_t>(n); ++i) {
    const float v = static_cast<float>(snapshot.positions[static_cast<Eigen::Index>(i)]);
    std::memcpy(frame.data() + 16 + 4 * i, &v, 4);
  }
  return frame;
}

}  // namespace shapectl::server
