#pragma once
// Eigen values as JSON, one encoding each, for every result file, log and message that writes
// them. Numbers go in as they are: JSON text has no NaN or infinity and dump() writes them as
// null (results are checked with first_non_finite, io/json_output.hpp, before they are written).
// Input files and client messages are read with JsonInput (vec3, numbers), which checks them.
#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <shapectl/types.hpp>

namespace shapectl {

nlohmann::json vec3_json(const Vec3& v);                      // [x, y, z]
nlohmann::json points_json(const std::vector<Vec3>& points);  // [[x, y, z], ...]
nlohmann::json positions_json(const Positions& x);            // stacked 3n → [[x0, y0, z0], ...]
nlohmann::json vector_json(const Eigen::VectorXd& v);         // [v0, v1, ...]: joints, limits
// A vector_json array read back (from a file we wrote: a session log). A null element (a
// non-finite number written) becomes `null_value`; without one, any non-number is a
// nlohmann::json::type_error.
Eigen::VectorXd vector_from_json(const nlohmann::json& j,
                                 std::optional<double> null_value = std::nullopt);

// Poses: three encodings, each part of a format that cannot change.
//
// Scene files (SCENE.json "object.pose", read by scene_io's read_pose, written by `author`):
//   {"position": [x, y, z], "rpy": [roll, pitch, yaw]}, metres and radians, URDF's fixed-axis
//   convention: roll about x, then pitch about y, then yaw about z.
nlohmann::json scene_pose_json(const Eigen::Isometry3d& T);
Mat3 rotation_from_rpy(const Vec3& rpy);
Vec3 rpy_from_rotation(const Mat3& rotation);
// The CLI's result files (`kinematics` "links", `statics`/`solve` "tools"):
//   {"position": [x, y, z], "rotation": [[r00, r01, r02], [r10, r11, r12], [r20, r21, r22]]}
//   (the rotation matrix by rows).
nlohmann::json result_pose_json(const Vec3& position, const Mat3& rotation);
// The WebSocket messages of `shapectl serve` (docs/gui.md): the 4×4 matrix as 16 numbers in
// column-major order (three.js Matrix4.fromArray).
nlohmann::json message_pose_json(const Eigen::Isometry3d& T);

}  // namespace shapectl
