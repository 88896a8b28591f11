#pragma once
// Shared pieces of the `shapectl` Python module: the Python-side holders of the library's
// objects, conversions between Eigen and numpy, and one bind_* function per concept (each in its
// own file). Arrays go out as float64 numpy arrays in the shapes Python users expect: positions
// (n, 3), joints (m,), sensitivities (3n, m), rotations (3, 3).
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <nlohmann/json.hpp>

#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/joint_limits.hpp>
#include <shapectl/robot/robot_model.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/gripped_object.hpp>

#include "strict_scalars.hpp"

namespace shapectl::python {

namespace py = pybind11;

// A computation that ran but failed (the CLI's exit 2): raised as shapectl.SolverError.
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A loaded scene and, when it has a robot, the gripped object built from it once (immutable,
// shared by every call and thread that uses the scene).
struct SceneHandle {
  std::shared_ptr<const Scene> scene;
  std::shared_ptr<const GrippedObject> object;  // null without a robot
  // The statics workspaces of every call on this scene (thread-safe): a batch's solves, e.g. a
  // Dask worker's tasks, share their symbolic analyses.
  std::shared_ptr<WorkspacePool> workspaces = WorkspacePool::create();
  // A scene given as a dict: its JSON text, file names absolute. Null: scene->source is its file.
  std::shared_ptr<const std::string> document;
  const GrippedObject& gripped() const;  // InputError if the scene has no robot
};

// The handle of a scene read from a file (no document) or a dict; builds the gripped object.
SceneHandle scene_handle(Scene scene, std::shared_ptr<const std::string> document = nullptr);
// A dict of SCENE.json's schema, file names relative to `base_dir`, read as load_scene reads a
// file; messages name it "scene".
SceneHandle scene_from_dict(const py::handle& d, const std::filesystem::path& base_dir);
// The scene as a dict of SCENE.json's schema with its current values (scene_json_with_values):
// file names absolute, or relative to `base_dir` when given.
py::object scene_to_dict(const SceneHandle& s,
                         const std::optional<std::filesystem::path>& base_dir);

// A robot model and, optionally, its collision spheres.
struct RobotHandle {
  std::shared_ptr<const RobotModel> model;
  std::shared_ptr<const CollisionModel> collisions;  // may be null
};

// A pose in the world frame: position (m) and rotation matrix.
struct Pose {
  Vec3 position = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
};

// Stacked 3n positions as an (n, 3) array.
py::array_t<double> positions_array(const Positions& x);
// Arrays in (input_conversion.cpp): a numpy array of integer or floating dtype, or a list or
// tuple (of rows) of ints and floats; dtype, shape and size are checked before anything is
// copied. TypeError for a wrong type (bool, str, complex, object, masked), ValueError (an
// InputError naming `what`) for a wrong shape or size or a non-finite value.
// An (n, 3) or (3n,) array as stacked positions.
Positions positions_from(const py::handle& array, int node_count, const std::string& what);
// A (k, 3) array of points, k from min_points to max_points.
std::vector<Vec3> points_from(const py::handle& array, const std::string& what,
                              std::size_t min_points, std::size_t max_points);
// θ from None (→ defaults), a {name: rad} dict (others keep `defaults`, names checked as in
// JOINTS.json) or an (m,) array.
Eigen::VectorXd joints_from(const py::handle& joints, const RobotModel& robot,
                            const Eigen::VectorXd& defaults);
// A str or os.PathLike as a path; InputError naming `what` and `expected` for anything else.
std::filesystem::path path_from(const py::handle& value, const std::string& what,
                                const std::string& expected);
// A TARGETS.json path (str or os.PathLike) or a dict of its schema, read as the CLI reads the
// file (a dict's JSON at most `max_dict_bytes`); `source` receives the name messages use (the
// path, or "targets" for a dict).
TargetsInput read_targets_from(const py::handle& targets, int node_count, std::string& source,
                               std::size_t max_dict_bytes = max_json_file_bytes);
// A Python value (dicts, lists, numbers, numpy arrays) as JSON, parsed strictly as `source`:
// at most `max_bytes` of JSON text (a file's limit by default), stopped as soon as it is over
// (numpy arrays checked against the bytes left before they are converted); NaN, complex
// numbers, object arrays, masked arrays and other types refused.
nlohmann::json json_from(const py::handle& value, const std::string& source,
                         std::size_t max_bytes = max_json_file_bytes);

// Each end effector's tool pose at θ (the CLI's "tools").
std::map<std::string, Pose> tool_poses(const Scene& scene, const Eigen::VectorXd& joints);
// Every joint of `full_joints` outside its hard limits (the CLI's "limit_violations").
std::vector<LimitViolation> violations_at(const RobotModel& robot, const Eigen::VectorXd& active);

// A result's contacts with the scene's obstacles and with itself (docs/contact.md): computed
// without the GIL, handed to Python as a dict by contacts_dict.
struct ContactsResult {
  ContactSummary summary;  // empty without obstacles
  std::vector<std::string> obstacle_names;
  std::optional<SelfContactSummary> self;  // none without self-contact
};
// The contacts at x; none without a contact term or a self-contact term (both null).
std::optional<ContactsResult> contacts_at(const ObstacleContact* contact, const SelfContact* self,
                                          const Positions& x);
// {"count", "min_distance" (m; None without a pair within the contact distance), "force_total"
// ((3,) N, the obstacles' force on the object), "by_obstacle": {name: {"count", "force"}}}, plus
// "self": {"count", "min_distance"} with self-contact, the fields of RESULT.json's "contacts";
// None without obstacles and self-contact.
py::object contacts_dict(const std::optional<ContactsResult>& contacts);

void bind_scene(py::module_& m);
void bind_statics(py::module_& m);
void bind_kinematics(py::module_& m);
void bind_solve(py::module_& m);
void bind_controller(py::module_& m);
void bind_calibration(py::module_& m);
void bind_runtime(py::module_& m);

}  // namespace shapectl::python
