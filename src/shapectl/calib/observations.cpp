#include <shapectl/calib/observations.hpp>

#include <algorithm>
#include <set>
#include <sstream>
#include <string>

#include <shapectl/calib/depth_image_file.hpp>
#include <shapectl/calib/point_cloud_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/joints_file.hpp>
#include <shapectl/scene_io/scene_file.hpp>  // read_loads, read_pose

namespace shapectl {

namespace {

// θ with every active joint named; size 0 for a scene without a robot.
Eigen::VectorXd read_frame_joints(const JsonInput& frame, const RobotModel* robot) {
  if (!robot) {
    // {} says "no joints" as well as leaving the key out (a program writing frames generically).
    if (frame.has("joints") &&
        !(frame.at("joints").is_object() && frame.at("joints").keys().empty()))
      frame.at("joints").fail_problem("the scene has no robot: expected no joints (or {})");
    return {};
  }
  const JsonInput joints = frame.at("joints");
  if (!joints.is_object()) joints.fail("an object of joint values");
  // A measured pose is complete: a joint left out must not silently read as 0.
  for (const std::string& name : robot->active_joint_names())
    if (!joints.has(name))
      throw InputError(joints.source(), joints.path(),
                       "missing active joint '" + name + "' (every active joint needs a value)");
  // read_joints (JOINTS.json) checks that each name is an active joint and each value a finite
  // number; the frame is wrapped so that its messages name "frames[i].joints.<name>".
  nlohmann::json wrapped = nlohmann::json::object();
  wrapped["joints"] = joints.raw();
  const Eigen::VectorXd theta =
      read_joints(JsonInput(std::move(wrapped), frame.source(), frame.path()), *robot,
                  Eigen::VectorXd::Zero(robot->active_count()));
  // A pose the robot cannot take is not a measurement: calibration would walk the model there
  // from the reference joints (calib/joint_path.hpp), and the feedback would compare it.
  const Eigen::VectorXd lower = robot->lower_limits(), upper = robot->upper_limits();
  const std::vector<std::string> names = robot->active_joint_names();
  for (Eigen::Index k = 0; k < theta.size(); ++k)
    if (!(theta[k] >= lower[k] - observation_joint_margin &&
          theta[k] <= upper[k] + observation_joint_margin)) {
      std::ostringstream expected;
      expected << "a value within the joint's limits [" << lower[k] << ", " << upper[k]
               << "] give or take " << observation_joint_margin;
      joints.at(names[static_cast<std::size_t>(k)]).fail(expected.str());
    }
  return theta;
}

std::vector<ObservedMarker> read_markers(const JsonInput& list, int node_count) {
  if (list.size() > max_markers_per_frame)
    list.fail_problem(std::to_string(list.size()) + " markers, more than the limit of " +
                      std::to_string(max_markers_per_frame));
  std::vector<ObservedMarker> markers;
  std::set<int> seen;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const JsonInput m = list.at(k);
    m.expect_only({"node", "position"});
    const int node = static_cast<int>(m.at("node").integer_in(0, node_count - 1));
    if (!seen.insert(node).second) m.at("node").fail("a node without another marker in this frame");
    markers.push_back(
        {node, m.at("position").vec3_within(max_observation_distance, "a point", "m")});
  }
  return markers;
}

std::vector<Vec3> read_inline_points(const JsonInput& list) {
  if (list.size() > max_point_cloud_points)
    list.fail_problem(std::to_string(list.size()) + " points, more than the limit of " +
                      std::to_string(max_point_cloud_points));
  std::vector<Vec3> points(list.size());
  for (std::size_t k = 0; k < list.size(); ++k)
    points[k] = list.at(k).vec3_within(max_observation_distance, "a point", "m");
  return points;
}

std::vector<Vec3> read_points_file(const JsonInput& field, const ObservationContext& context) {
  if (!context.allow_points_files)
    field.fail_problem(
        "point cloud files are read only from an observations file; expected \"points\"");
  const std::string name = field.string();
  if (name.empty()) field.fail("a file name");
  const std::filesystem::path file = field.directory() / name;  // an absolute name stays as it is
  std::vector<Vec3> points;
  try {
    points = read_point_cloud(file);
  } catch (const InputError& e) {
    field.fail_problem(std::string("cannot read the point cloud: ") + e.what());
  }
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!(points[i].norm() <= max_observation_distance)) {
      std::ostringstream problem;
      problem << "in " << file.string() << ": point " << i << " is " << points[i].norm()
              << " m from the origin, more than " << max_observation_distance << " m";
      field.fail_problem(problem.str());
    }
  return points;
}

// The frame's own loads, read and checked as the scene's (scene_io/scene_file.hpp).
std::vector<NodeLoad> read_frame_loads(const JsonInput& list, const ObservationContext& context) {
  if (!list.is_array()) list.fail("a list of loads [{\"nodes\" or \"box\", \"force\"}]");
  std::vector<NodeLoad> loads = read_loads(list, *context.mesh);
  refuse_empty_loads(list, loads);
  return loads;
}

}  // namespace

ObservationFrame read_observation_frame(const JsonInput& frame, const ObservationContext& context) {
  frame.expect_only({"joints", "markers", "points", "points_file", "depth_image", "sigma", "time",
                     "loads", "object_pose"});
  ObservationFrame out;
  out.joints = read_frame_joints(frame, context.robot);
  if (frame.has("markers")) out.markers = read_markers(frame.at("markers"), context.node_count);
  if (frame.has("points") + frame.has("points_file") + frame.has("depth_image") > 1)
    frame.fail_problem(
        "more than one of \"points\", \"points_file\" and \"depth_image\"; expected one");
  if (frame.has("points")) out.points = read_inline_points(frame.at("points"));
  if (frame.has("points_file")) out.points = read_points_file(frame.at("points_file"), context);
  if (frame.has("depth_image")) {
    if (!context.allow_points_files)
      frame.at("depth_image")
          .fail_problem(
              "depth images are read only from an observations file; expected \"points\"");
    DepthImageObservation depth = read_depth_image(frame.at("depth_image"));
    out.points = std::move(depth.points);
    out.camera = depth.camera;
  }
  if (out.markers.empty() && out.points.empty())
    frame.fail_problem("nothing observed; expected at least one marker or one point");
  if (frame.has("sigma")) out.sigma = frame.at("sigma").positive();
  if (frame.has("time")) out.time = frame.at("time").non_negative();
  // Conditions change the model a frame is compared with: read where the scene is at hand (a
  // file, Python), not from a live channel, whose frames the controller compares as they come.
  for (const char* key : {"loads", "object_pose"})
    if (frame.has(key) && !context.mesh)
      frame.at(key).fail_problem(
          "per-frame conditions are read only from an observations file (or Python), not from a "
          "live channel");
  if (frame.has("loads")) out.loads = read_frame_loads(frame.at("loads"), context);
  if (frame.has("object_pose")) out.object_pose = read_pose(frame.at("object_pose"));
  return out;
}

Observations read_observations(const JsonInput& json, const ObservationContext& context) {
  json.expect_only({"frames", "priors", "bounds"});
  const JsonInput frames = json.at("frames");
  if (frames.size() == 0) frames.fail("a non-empty list of frames");
  if (frames.size() > max_observation_frames)
    frames.fail_problem(std::to_string(frames.size()) + " frames, more than the limit of " +
                        std::to_string(max_observation_frames));
  Observations out;
  // --prior's and --bounds' grammar, their messages under the file's field.
  try {
    if (json.has("priors")) out.priors = parse_priors(json.at("priors").string());
  } catch (const std::invalid_argument& e) {
    json.at("priors").fail_problem(e.what());
  }
  try {
    if (json.has("bounds")) out.bounds = parse_bounds(json.at("bounds").string());
  } catch (const std::invalid_argument& e) {
    json.at("bounds").fail_problem(e.what());
  }
  std::size_t total_points = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    out.frames.push_back(read_observation_frame(frames.at(k), context));
    total_points += out.frames.back().points.size();
    if (total_points > max_observed_points)
      frames.at(k).fail_problem("more than the limit of " + std::to_string(max_observed_points) +
                                " points in all frames together");
  }
  return out;
}

int camera_count(const Observations& observations) {
  int count = 0;
  for (const ObservationFrame& f : observations.frames)
    if (f.camera) count = std::max(count, f.camera->index + 1);
  return count;
}

Observations load_observations(const std::filesystem::path& file, ObservationContext context) {
  context.allow_points_files = true;
  return read_observations(JsonInput::load(file), context);
}

}  // namespace shapectl
