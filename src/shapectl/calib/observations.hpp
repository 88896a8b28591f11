#pragma once
// What was measured of the real object, frame by frame: the robot's joints, tracked markers at
// known mesh nodes and/or an unordered point cloud; world frame, metres. OBSERVATIONS.json:
//   {"frames": [{"joints": {"yumi_joint_1_l": 0.1, ...},
//                "markers": [{"node": 12, "position": [x, y, z]}, ...],
//                "points": [[x, y, z], ...]   or   "points_file": "cloud.ply"
//                                             or   "depth_image": {"file": "d.png", ...},
//                "sigma": 0.0005, "time": 12.5,
//                "loads": [{"box": {...}, "force": [0, 0, -0.5]}]}],
//    "priors": "youngs_modulus=50%", "bounds": "density=30:60"}
// joints: every active joint of the robot (rad, m for prismatic), none other, each within its
//   limits give or take observation_joint_margin; omitted for a scene without a robot. markers:
//   distinct nodes. points_file: .xyz, .ply or .npy (calib/point_cloud_file.hpp), relative to the
//   JSON file's directory. depth_image: a depth camera's image as the frame's points
//   (calib/depth_image_file.hpp), from a file as points_file. Each frame observes at least one
//   marker or one point. sigma: the measurement noise (standard deviation, m, > 0, default
//   default_observation_sigma). time: seconds (>= 0), optional. loads: the loads on the object in
//   this frame (a weight hung from its free end), with the scene's "loads" schema and meaning (N,
//   world frame, shared equally by the selected nodes); given, they replace the scene's loads for
//   this frame ([] for none), omitted, the scene's apply. A series of known loads is what separates
//   stiffness from density (docs/calibration.md, "Load series"). object_pose: where the object
//   (with its clamp: its fixed nodes) was in this frame, {"position", "rpy"} as the scene's
//   object.pose, which it replaces for this frame; a known condition (a clamp turned between
//   frames), never fitted. priors, bounds (optional): what the one who measured knows, with
//   --prior's and --bounds' syntax and meaning (calib/parameter_priors.hpp); the command line's
//   entries win over the file's.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include <shapectl/calib/parameter_priors.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/robot/robot_model.hpp>
#include <shapectl/sim/scene.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

// m: between a good marker tracker (~0.1 mm) and a depth camera at arm's length (a few mm).
inline constexpr double default_observation_sigma = 0.001;
// Bounds checked before the lists are read. A frame's points are at most
// max_point_cloud_points (2 million), inline or from a file; a JSON file is at most
// max_json_file_bytes (8 MB, ~250,000 inline points), so large clouds go in points files.
inline constexpr std::size_t max_observation_frames = 10'000;
inline constexpr std::size_t max_markers_per_frame = 100'000;
inline constexpr std::size_t max_observed_points = 20'000'000;  // all frames together: 480 MB
inline constexpr double max_observation_distance = 1e3;         // m from the world origin
// rad (m for prismatic joints): how far past a limit a measured joint may read (encoder noise,
// the controller's own tolerance at a limit); further is not a pose the robot can take.
inline constexpr double observation_joint_margin = 0.01;
// Depth cameras told apart by a depth image's "camera" (0 to max_cameras − 1).
inline constexpr int max_cameras = 16;

struct ObservedMarker {
  int node;       // mesh node the marker sits on
  Vec3 position;  // world frame, m
};

// The depth camera a frame's points came from: with --fit camera_poses they move with its
// fitted pose correction (calib/model_parameters.hpp).
struct FrameCamera {
  int index = 0;                 // the depth image's "camera"
  Vec3 position = Vec3::Zero();  // its origin, world frame, m (camera_pose's position)
};

struct ObservationFrame {
  Eigen::VectorXd joints;               // θ, size robot.active_count(); size 0 without a robot
  std::vector<ObservedMarker> markers;  // distinct nodes
  std::vector<Vec3> points;             // unordered cloud, world frame, m
  double sigma = default_observation_sigma;      // measurement noise (standard deviation), m
  std::optional<double> time;                    // s
  std::optional<std::vector<NodeLoad>> loads;    // replaces the scene's loads; nullopt: the scene's
  std::optional<Eigen::Isometry3d> object_pose;  // replaces T_world_object; nullopt: the scene's
  std::optional<FrameCamera> camera;             // the points are a depth image's
};

struct Observations {
  std::vector<ObservationFrame> frames;  // at least one
  // "priors" and "bounds": --prior's and --bounds' defaults changed by the file's entries.
  std::optional<CalibrationPriors> priors = std::nullopt;
  std::optional<MaterialBounds> bounds = std::nullopt;
};

struct ObservationContext {
  int node_count = 0;                 // of the object's mesh
  const RobotModel* robot = nullptr;  // null: a scene without a robot (frames have no joints)
  // The object's rest mesh (object coordinates): a frame's "loads" select nodes of it; null (a
  // live channel): a frame with loads or an object_pose is refused.
  const TetMesh* mesh = nullptr;
  // Whether a frame may name a "points_file" or a "depth_image". load_observations allows it; JSON
  // from a network message leaves it off, so that a client cannot make the server read its files.
  bool allow_points_files = false;
};

// Throws InputError naming the source and field ("obs.json: frames[3].markers[0].node: expected
// a whole number from 0 to 424, got 500"): an empty or too long list of frames, a frame with
// nothing observed, a node out of range or repeated, non-finite numbers, points beyond
// max_observation_distance, a joint missing, not active or outside its limits (± the margin),
// joints without a robot, more than one of points, points_file and depth_image, a bad depth
// image (calib/depth_image_file.hpp), loads as the scene file refuses them (or on no node, or
// without context.mesh), both points and points_file, a points file that cannot be read (the
// message names it and the problem), a points_file where they are not allowed, priors or bounds
// that --prior or --bounds would refuse, unknown keys, sizes over the limits above.
Observations read_observations(const JsonInput& json, const ObservationContext& context);
// One frame, e.g. from a WebSocket message: the object inside "frames" above.
ObservationFrame read_observation_frame(const JsonInput& frame, const ObservationContext& context);
// 1 + the largest camera index of the frames' depth images; 0 without any.
int camera_count(const Observations& observations);
// Reads the file with points files allowed, relative to its directory.
Observations load_observations(const std::filesystem::path& file, ObservationContext context);

}  // namespace shapectl
