#include <shapectl/server/session.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>

#include <shapectl/control/centerline.hpp>
#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/session_log.hpp>
#include <shapectl/link/robot_link.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/runtime/runtime_policy.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/server/contact_message.hpp>
#include <shapectl/server/http_rules.hpp>  // robot_mesh_prefix
#include <shapectl/sim/object_statics.hpp>

namespace shapectl::server {

namespace {

// JSON has no infinity: unbounded limits and clearances go out as null.
nlohmann::json finite_or_null(double v) {
  if (std::isfinite(v)) return v;
  return nullptr;
}

// [[node, x, y, z], ...]: the last observation's markers, for the page to draw.
nlohmann::json observed_markers_json(const std::vector<std::pair<int, Vec3>>& markers) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [node, p] : markers) out.push_back({node, p.x(), p.y(), p.z()});
  return out;
}

// The model the controller works with now (its material and grip offsets).
nlohmann::json model_json(const ControllerSnapshot& s, const Scene& scene) {
  nlohmann::json offsets = nlohmann::json::array();
  for (std::size_t k = 0; k < s.grip_offsets.size() && k < scene.grips.size(); ++k) {
    const nlohmann::json pose = scene_pose_json(s.grip_offsets[k]);
    offsets.push_back(
        {{"end_effector", scene.robot->end_effectors[scene.grips[k].end_effector].name},
         {"position", pose.at("position")},
         {"rpy", pose.at("rpy")}});
  }
  return {{"youngs_modulus", youngs_modulus_of(s.material)},
          {"poisson_ratio", poisson_ratio_of(s.material)},
          {"density", s.material.density},
          {"grip_offsets", offsets},
          {"updates", s.model_updates}};
}

// The session's calibration: whether one runs, and the newest result (docs/gui.md).
// The closest checked sphere pair, as indices into the scene message's collision_spheres.
nlohmann::json closest_pair_json(const SphereClearance& pair) {
  if (pair.first < 0) return nullptr;
  return {{"spheres", {pair.first, pair.second}}, {"clearance", finite_or_null(pair.clearance)}};
}

nlohmann::json calibration_json(const OnlineCalibrationStatus& c) {
  nlohmann::json result = nullptr;
  if (const CalibrationResult* r = c.result.get()) {
    nlohmann::json parameters = nlohmann::json::array();
    for (const FittedParameter& p : r->parameters)
      parameters.push_back({{"name", p.name},
                            {"unit", p.unit},
                            {"initial", finite_or_null(p.initial)},
                            {"fitted", finite_or_null(p.fitted)},
                            {"standard_deviation", finite_or_null(p.standard_deviation)},
                            {"held", p.held},
                            {"verdict", to_string(p.verdict)},
                            {"prior", p.prior > 0 ? finite_or_null(p.prior) : nullptr},
                            {"implausible", p.implausible},
                            {"trades_off_with", p.trades_off_with},
                            {"suggestion", p.suggestion}});
    nlohmann::json unidentified = nlohmann::json::array();
    for (const UnidentifiedDirection& d : r->unidentified)
      unidentified.push_back(
          {{"held", d.held}, {"standard_deviation", finite_or_null(d.standard_deviation)}});
    result = {{"parameters", parameters},
              {"unidentified", unidentified},
              {"rms_before", finite_or_null(r->rms_before)},
              {"rms_after", finite_or_null(r->rms_after)},
              {"iterations", r->iterations},
              {"seconds", r->seconds},
              {"converged", r->converged},
              {"reason", r->reason},
              {"applied", c.applied}};
  }
  return {{"automatic", c.automatic}, {"running", c.running}, {"frames", c.frames},
          {"runs", c.runs},           {"error", c.error},     {"result", result}};
}

const char* kind_name(Shape::Kind kind) {
  switch (kind) {
    case Shape::Kind::Sphere: return "sphere";
    case Shape::Kind::Box: return "box";
    case Shape::Kind::Cylinder: return "cylinder";
    case Shape::Kind::Mesh: return "mesh";
  }
  return "sphere";
}

nlohmann::json shape_json(const Shape& s) {
  return {{"kind", kind_name(s.kind)},
          {"pose", message_pose_json(s.T_link_shape)},
          {"size", vec3_json(s.box_size)},
          {"radius", s.radius},
          {"length", s.length},
          {"color", s.rgba ? nlohmann::json(std::vector<double>(s.rgba->data(), s.rgba->data() + 4))
                           : nlohmann::json(nullptr)}};
}

// A mesh visual's file for the page: "url" /robot-mesh/<n>.<ext> (n: its index in `meshes`,
// the table the server answers from), or null with "missing" when it cannot be drawn.
void add_mesh_file(nlohmann::json& visual, const VisualMesh& mesh, std::size_t index,
                   const RobotModel& model) {
  const Shape& s = model.links()[static_cast<std::size_t>(mesh.link)]
                       .visual_shapes[static_cast<std::size_t>(mesh.shape)];
  visual["scale"] = vec3_json(s.mesh_scale);
  visual["format"] = to_string(mesh.format);
  visual["file"] = s.mesh_filename;
  visual["url"] = mesh.file ? nlohmann::json(std::string(robot_mesh_prefix) +
                                             std::to_string(index) + "." + to_string(mesh.format))
                            : nlohmann::json(nullptr);
  if (!mesh.file) visual["missing"] = visual_mesh_warning(model, mesh);
}

// The active joints (θ indices) in chain order: each arm shoulder to wrist (a URDF may list
// them in any order), the arms in θ order of their first joints; with each one's position in
// its chain (1: the first movable joint from the root).
struct ChainOrder {
  std::vector<int> joints;
  std::vector<int> positions;  // per θ index
};
ChainOrder chain_order(const RobotModel& model) {
  const auto count = static_cast<std::size_t>(model.active_count());
  ChainOrder out;
  out.positions.assign(count, 0);
  std::vector<int> first(count, 0);  // per θ index: the θ index of its chain's first joint
  for (std::size_t k = 0; k < count; ++k) {
    // Up from the joint to the root, counting the active joints on the way.
    int depth = 0, top = static_cast<int>(k);
    for (int joint = model.active_joints()[k]; joint >= 0;) {
      if (model.active_index(joint) >= 0) ++depth, top = model.active_index(joint);
      joint = model.links()[model.joints()[joint].parent_link].parent_joint;
    }
    out.positions[k] = depth;
    first[k] = top;
  }
  out.joints.resize(count);
  for (std::size_t k = 0; k < count; ++k) out.joints[k] = static_cast<int>(k);
  std::stable_sort(out.joints.begin(), out.joints.end(), [&](int a, int b) {
    return std::pair(first[a], out.positions[a]) < std::pair(first[b], out.positions[b]);
  });
  return out;
}

// Per θ index: the name of the end effector the joint moves (the page groups the joints by arm),
// null for a joint that moves none or several of them.
nlohmann::json joint_arms(const RobotSetup& setup) {
  const RobotModel& model = *setup.model;
  constexpr int kNone = -1, kSeveral = -2;
  std::vector<int> arm(static_cast<std::size_t>(model.active_count()), kNone);
  for (std::size_t e = 0; e < setup.end_effectors.size(); ++e) {
    // Up from the end effector's link to the root.
    for (int joint =
             model.links()[static_cast<std::size_t>(setup.end_effectors[e].link)].parent_joint;
         joint >= 0; joint = model.links()[model.joints()[joint].parent_link].parent_joint) {
      const int k = model.active_index(joint);
      if (k >= 0) arm[k] = arm[k] == kNone ? static_cast<int>(e) : kSeveral;
    }
  }
  nlohmann::json out = nlohmann::json::array();
  for (const int e : arm)
    out.push_back(e >= 0 ? nlohmann::json(setup.end_effectors[static_cast<std::size_t>(e)].name)
                         : nlohmann::json());
  return out;
}

nlohmann::json robot_json(const RobotSetup& setup, const std::vector<VisualMesh>& meshes) {
  const RobotModel& model = *setup.model;
  const ChainOrder chain = chain_order(model);
  nlohmann::json links = nlohmann::json::array();
  std::size_t next_mesh = 0;  // meshes are in link and visual order
  for (const Link& link : model.links()) {
    nlohmann::json visuals = nlohmann::json::array();
    for (const Shape& s : link.visual_shapes) {
      visuals.push_back(shape_json(s));
      if (s.kind == Shape::Kind::Mesh && next_mesh < meshes.size()) {
        add_mesh_file(visuals.back(), meshes[next_mesh], next_mesh, model);
        ++next_mesh;
      }
    }
    links.push_back({{"name", link.name}, {"visuals", visuals}});
  }
  nlohmann::json spheres = nlohmann::json::array();
  if (setup.collisions)
    for (const CollisionSphere& s : setup.collisions->spheres())
      spheres.push_back(
          {{"link", s.link}, {"center", vec3_json(s.center_link)}, {"radius", s.radius}});
  nlohmann::json end_effectors = nlohmann::json::array();
  for (const EndEffector& e : setup.end_effectors)
    end_effectors.push_back({{"name", e.name}, {"link", e.link}, {"tcp", vec3_json(e.tcp_link)}});
  return {{"name", model.name()},
          {"links", links},
          {"joint_names", model.active_joint_names()},
          {"lower_limits", vector_json(model.lower_limits())},
          {"upper_limits", vector_json(model.upper_limits())},
          {"chain_order", chain.joints},
          {"chain_positions", chain.positions},
          {"joint_arms", joint_arms(setup)},
          {"reference_joints", vector_json(setup.reference_joints)},
          {"end_effectors", end_effectors},
          {"collision_spheres", spheres}};
}

// What the page must show as a warning: each visual mesh that cannot be drawn.
nlohmann::json mesh_warnings(const Scene& scene, const std::vector<VisualMesh>& meshes) {
  nlohmann::json out = nlohmann::json::array();
  for (const VisualMesh& m : meshes)
    if (!m.file && scene.robot) out.push_back(visual_mesh_warning(*scene.robot->model, m));
  return out;
}

nlohmann::json link_status_json(const LinkStatus& s) {
  return {{"kind", s.kind},
          {"connected", s.connected},
          {"armed", s.armed},
          {"feedback_age", finite_or_null(s.feedback_age)},
          {"reason", s.reason},
          {"measured", vector_json(s.measured)},
          {"commanded", vector_json(s.commanded)}};
}

// The link poses at the measured joints (the ghost robot), encoded as a state's "links"; null
// without a robot or before the first feedback.
nlohmann::json measured_links_json(const Scene& scene, const LinkStatus& status) {
  if (!scene.robot || status.measured.size() != scene.robot->model->active_count()) return nullptr;
  nlohmann::json links = nlohmann::json::array();
  for (const auto& T : forward_kinematics(*scene.robot->model, status.measured).T_world_link)
    links.push_back(message_pose_json(T));
  return links;
}

// Whether `entry` loads with a robot whose active joints are `joints`.
bool has_joints(const SceneEntry& entry, const std::vector<std::string>& joints) {
  try {
    const Scene scene = load_scene(entry.path);
    return scene.robot && scene.robot->model->active_joint_names() == joints;
  } catch (const InputError&) {
    return false;  // it could not be switched to either
  }
}

}  // namespace

void log_snapshot(SessionLog& log, const ControllerSnapshot& s) {
  log.write("optimizer", {{"sequence", s.sequence},
                          {"status", to_string(s.status)},
                          {"joints", vector_json(s.joints)},
                          {"safe", s.safe},
                          {"error_mean", s.error.mean},
                          {"error_max", s.error.max},
                          {"objective", s.objective},
                          {"iterations", s.iterations}});
}

nlohmann::json gate_json(const GateCounts& g) {
  return {{"markers_checked", g.markers_checked},
          {"markers_rejected", g.markers_rejected},
          {"frames_checked", g.frames_checked},
          {"frames_rejected", g.frames_rejected}};
}

nlohmann::json authority_json(const FeedbackAuthority& a) {
  return {{"max_correction", a.max_correction},
          {"max_correction_rate", a.max_correction_rate},
          {"largest", a.largest},
          {"rate_limited", a.rate_limited},
          {"clamped", a.clamped},
          {"trust_region", a.trust_region},
          {"joint_offset", a.joint_offset}};
}

void log_gate(SessionLog& log, const ControllerSnapshot& s, GateCounts& logged) {
  if (s.gate.markers_rejected == logged.markers_rejected &&
      s.gate.frames_rejected == logged.frames_rejected)
    return;
  logged = s.gate;
  log.write("gate", {{"gate", gate_json(s.gate)},
                     {"authority", authority_json(s.authority)},
                     {"problem", s.observation_problem}});
}

std::vector<SceneEntry> find_bundled_scenes(const std::filesystem::path& directory) {
  std::vector<SceneEntry> scenes;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec)) {
    if (entry.path().extension() != ".json" || !entry.is_regular_file(ec)) continue;
    std::ifstream in(entry.path());
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_object() && j.contains("robot"))
      scenes.push_back({entry.path().filename().string(), entry.path()});
  }
  std::sort(scenes.begin(), scenes.end(),
            [](const SceneEntry& a, const SceneEntry& b) { return a.name < b.name; });
  return scenes;
}

Session::Session(const std::filesystem::path& scene, std::vector<SceneEntry> scenes,
                 RobotLink* link, ControllerOptions options, OnlineCalibrationOptions calibration,
                 std::vector<std::filesystem::path> package_paths)
    : scenes_(std::move(scenes)),
      link_(link),
      options_(options),
      calibration_options_(std::move(calibration)),
      package_paths_(std::move(package_paths)) {
  // The process's tuning (docs/runtime.md), unless its program chose it: before any solve runs.
  runtime::ensure_runtime_policy();
  const std::string name = scene.filename().string();
  auto same = [&](const SceneEntry& e) { return e.name == name; };
  auto it = std::find_if(scenes_.begin(), scenes_.end(), same);
  if (it == scenes_.end()) {
    scenes_.push_back({name, scene});
    it = scenes_.end() - 1;
  } else {
    it->path = scene;  // the file asked for wins over a bundled one of the same name
  }
  load(*it);
  // A robot link drives one robot: offering a scene that load() would refuse only confuses.
  if (link_) {
    const std::vector<std::string> joints = controller_->robot().active_joint_names();
    std::erase_if(scenes_, [&](const SceneEntry& e) {
      return e.name != scene_name_ && !has_joints(e, joints);
    });
    scene_description_ = describe_scene();  // its list of scenes
  }
}

Session::~Session() = default;

void Session::load(const SceneEntry& entry) {
  // Load first: a bad scene leaves the current one running.
  const Scene scene = load_scene(entry.path);
  if (!scene.robot)
    throw InputError(entry.path.string(), "robot", "missing: the GUI needs a scene with a robot");
  // A robot link drives one robot: every scene must have the same joints as the first.
  if (link_ && controller_) {
    const auto joints =
        scene.robot ? scene.robot->model->active_joint_names() : std::vector<std::string>{};
    if (joints != controller_->robot().active_joint_names())
      throw InputError("message", "scene",
                       "a scene with the robot link's robot; " + entry.name + " has other joints");
  }
  auto controller = std::make_unique<Controller>(scene, options_);
  calibration_.reset();  // it refers to the old controller
  if (controller_) controller_->stop();
  controller_ = std::move(controller);
  // The controller's scene: with the linear solver of its options.
  calibration_ =
      std::make_unique<OnlineCalibration>(*controller_, controller_->scene(), calibration_options_);
  controller_->start();
  scene_name_ = entry.name;
  targets_ = {};
  history_.clear();
  started_ = std::chrono::steady_clock::now();
  last_edit_time_ = -1e9;
  snapshot_ = controller_->snapshot();
  logged_sequence_ = 0;
  logged_gate_ = {};  // a new controller counts from zero
  // Only an armed link has something to say about it (at start-up it is disarmed already).
  if (link_ && link_->status().armed) link_->disarm("scene changed to " + entry.name);
  robot_meshes_ = find_visual_meshes(*scene.robot->model, package_paths_);
  statics_ = scene.obstacles.empty() && !scene.contact.robot && !scene.contact.self
                 ? nullptr
                 : std::make_unique<ObjectStatics>(scene);
  contacts_ = nullptr;
  update_contacts();
  scene_description_ = describe_scene();
}

std::optional<std::filesystem::path> Session::robot_mesh_file(std::size_t index,
                                                              std::string_view extension) const {
  if (index >= robot_meshes_.size()) return std::nullopt;
  const VisualMesh& mesh = robot_meshes_[index];
  std::error_code error;
  if (!mesh.file || extension != to_string(mesh.format) ||
      std::filesystem::file_size(*mesh.file, error) > max_visual_mesh_bytes || error)
    return std::nullopt;
  return mesh.file;
}

double Session::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

ProtocolContext Session::context() const {
  ProtocolContext c;
  c.node_count = controller_->mesh().node_count();
  c.joint_names = snapshot_->joint_names;
  c.lower_limits = snapshot_->lower_limits;
  c.upper_limits = snapshot_->upper_limits;
  for (const auto& s : scenes_) c.scene_names.push_back(s.name);
  c.robot = &controller_->robot();
  return c;
}

Session::Reply Session::handle(std::string_view text) {
  Reply reply;
  nlohmann::json id;
  try {
    const Command command = parse_command(text, context());
    id = command.id;
    apply(command);
    reply.ok = true;
    reply.scene_changed = command.type == Command::Type::LoadScene;
    reply.text = ok_reply(id);
  } catch (const InputError& e) {
    if (id.is_null()) id = message_id(text);
    reply.text = error_reply(id, e.what());
    reply.log = e.what();
    if (is_observe_message(text)) ++observations_rejected_, observation_rejection_ = e.what();
  } catch (const std::exception& e) {
    if (id.is_null()) id = message_id(text);
    reply.text = error_reply(id, std::string("failed: ") + e.what());
    reply.log = std::string("failed: ") + e.what();
  }
  return reply;
}

void Session::apply(const Command& c) {
  using T = Command::Type;
  auto edited = [&] { last_edit_time_ = now(); };
  switch (c.type) {
    case T::Ping: break;
    case T::SetTarget:
    case T::RemoveTarget:
    case T::SetTargets: {
      ShapeTargets next = targets_;
      if (c.type == T::SetTargets) next = c.targets;
      const auto it = std::find(next.nodes.begin(), next.nodes.end(), c.node);
      const auto k = it - next.nodes.begin();
      if (c.type == T::SetTarget && it != next.nodes.end()) {
        next.positions[static_cast<std::size_t>(k)] = c.position;
      } else if (c.type == T::SetTarget) {
        next.nodes.push_back(c.node);
        next.positions.push_back(c.position);
      } else if (c.type == T::RemoveTarget) {
        if (it == next.nodes.end())
          throw InputError("message", "node", "a node that has a target", c.node);
        next.nodes.erase(it);
        next.positions.erase(next.positions.begin() + k);
      }
      if (next.empty()) controller_->clear_targets();
      else controller_->set_targets(next);
      targets_ = std::move(next);
      edited();
      break;
    }
    case T::ClearTargets:
      controller_->clear_targets();
      targets_ = {};
      edited();
      break;
    case T::SetCenterline:
      controller_->set_centerline(c.points);
      targets_ = {};
      edited();
      break;
    case T::SetPaused: controller_->set_paused(c.paused); break;
    // The Controller guards jogs (paused first, one step at most, quick jogs of two joints).
    case T::SetJoint: controller_->set_joint(c.joint, c.value); break;
    case T::SetJoints: controller_->set_joints(c.joints); break;
    case T::Reset:
      controller_->reset();
      targets_ = {};
      edited();
      break;
    case T::LoadScene: {
      const auto it = std::find_if(scenes_.begin(), scenes_.end(),
                                   [&](const SceneEntry& e) { return e.name == c.scene; });
      load(*it);  // parse_command admitted only known names
      // The optimizer events that follow belong to this scene (and have its joints).
      if (log_)
        log_->write_header("scene", {{"scene", std::filesystem::absolute(it->path).string()},
                                     {"joint_names", controller_->robot().active_joint_names()}});
      break;
    }
    case T::Arm: {
      if (!link_) throw InputError("message", "type", "no robot link in this session");
      std::string why_not;
      if (!link_->arm(&why_not)) throw InputError("message", "arm", "refused: " + why_not);
      break;
    }
    case T::Disarm:
      if (!link_) throw InputError("message", "type", "no robot link in this session");
      link_->disarm("disarmed from the GUI");
      break;
    case T::Observe: calibration_->observe(c.frame); break;
    case T::SetFeedback: controller_->set_feedback(c.on); break;
    case T::Calibrate: {
      std::string why_not;
      if (!calibration_->start(&why_not)) throw InputError("message", "calibrate", why_not);
      break;
    }
    case T::SetAutoCalibration: calibration_->set_automatic(c.on); break;
  }
}

namespace {
// Everything a state or positions frame carries, finite and within float range: the numbers
// of a snapshot that is not are never sent (the last good ones stay; see tick()).
bool publishable(const ControllerSnapshot& s) {
  auto ok = [](const auto& m) { return (m.array().abs() <= 1e30).all(); };
  for (const auto& T : s.T_world_link)
    if (!ok(T.matrix())) return false;
  for (const auto& p : s.targets.positions)
    if (!ok(p)) return false;
  for (const auto& p : s.centerline)
    if (!ok(p)) return false;
  return ok(s.joints) && ok(s.positions) && std::isfinite(s.error.mean) &&
         std::isfinite(s.error.max);
}
}  // namespace

void Session::tick() {
  auto next = controller_->snapshot();
  if (publishable(*next)) {
    snapshot_ = std::move(next);
  } else if (next->sequence != snapshot_->sequence) {
    // Geometry and numbers from the last good state; what the controller says from this one,
    // so pages see that something failed instead of a frozen state.
    auto shown = std::make_shared<ControllerSnapshot>(*snapshot_);
    shown->sequence = next->sequence;
    shown->status = next->status;
    shown->paused = next->paused;
    shown->last_error = "a state with non-finite numbers was not shown" +
                        (next->last_error.empty() ? std::string() : ": " + next->last_error);
    snapshot_ = std::move(shown);
  }
  const double t = now();
  history_.push_back({t, snapshot_->error.mean, t - last_edit_time_ < editing_window});
  while (history_.size() > history_capacity) history_.pop_front();
  if (link_) link_->set_target(snapshot_->joints, snapshot_->safe);
  if (log_ && snapshot_->sequence != logged_sequence_) {
    logged_sequence_ = snapshot_->sequence;
    log_snapshot(*log_, *snapshot_);
    log_gate(*log_, *snapshot_, logged_gate_);
  }
  if (world_ && link_) observe_world(t);
  calibration_->poll(t);
  update_contacts();
}

void Session::update_contacts() {
  const ObstacleContact* contact = statics_ ? statics_->contact() : nullptr;
  const SelfContact* self = statics_ ? statics_->self_contact() : nullptr;
  if ((!contact && !self) || (!contacts_.is_null() && snapshot_->sequence == contacts_sequence_))
    return;
  if (snapshot_->positions.size() != 3 * controller_->mesh().node_count()) return;  // none yet
  contacts_sequence_ = snapshot_->sequence;
  std::optional<SelfContactSummary> self_summary;
  if (self) self_summary = self->summary(snapshot_->positions);
  const SelfContactSummary* self_part = self_summary ? &*self_summary : nullptr;
  if (!contact) {
    ContactSummary none;
    none.min_distance = std::numeric_limits<double>::infinity();
    contacts_ = contacts_json(none, {}, max_contact_points, self_part);
    return;
  }
  // The forces at the stiffness the state was solved at (the adaptive barrier).
  const ObstacleContact scaled = contact->scaled(snapshot_->contact_scale);
  if (contact->moves() &&
      snapshot_->joints.size() == controller_->scene().robot->reference_joints.size()) {
    // Obstacles on links where the snapshot's joints put them.
    const ObstacleContact posed = scaled.posed(
        forward_kinematics(*controller_->scene().robot->model, snapshot_->joints).T_world_link);
    contacts_ = contacts_json(posed.summary(snapshot_->positions), posed.obstacles(),
                              max_contact_points, self_part);
    return;
  }
  contacts_ = contacts_json(scaled.summary(snapshot_->positions), scaled.obstacles(),
                            max_contact_points, self_part);
}

void Session::set_world(std::unique_ptr<SimulatedWorld> world) {
  if (!link_)
    throw InputError("serve", "--world", "a robot link (--robot sim) holding the world's object");
  world_ = std::move(world);
  scenes_.erase(std::remove_if(scenes_.begin(), scenes_.end(),
                               [&](const SceneEntry& e) { return e.name != scene_name_; }),
                scenes_.end());
  scene_description_ = describe_scene();  // its list of scenes
}

void Session::observe_world(double time) {
  const LinkStatus st = link_->status();
  if (st.measured.size() != snapshot_->joints.size()) return;  // no feedback yet
  world_->camera().marker_nodes = snapshot_->targets.nodes;
  const std::optional<ObservationFrame> frame = world_->step(time, st.measured);
  true_error_ = world_->true_error(snapshot_->targets);
  if (frame && !(frame->markers.empty() && frame->points.empty())) calibration_->observe(*frame);
}

bool Session::busy() const { return snapshot_->status == ControllerStatus::Optimizing; }

nlohmann::json Session::describe_scene() const {
  const Scene& scene = controller_->scene();
  const TetMesh& mesh = controller_->mesh();
  nlohmann::json triangles = nlohmann::json::array();
  for (const auto& t : mesh.surface_triangles())
    for (int v : t) triangles.push_back(v);
  nlohmann::json grips = nlohmann::json::array();
  for (const Grip& g : scene.grips) {
    const std::string name = scene.robot ? scene.robot->end_effectors[g.end_effector].name : "";
    grips.push_back({{"end_effector", name}, {"nodes", g.nodes}});
  }
  nlohmann::json bar = nullptr;
  if (const auto axis = find_bar_axis(mesh))
    bar = {{"center", vec3_json(axis->center)},
           {"direction", vec3_json(axis->direction)},
           {"length", axis->length},
           {"thickness", axis->thickness}};
  nlohmann::json scenes = nlohmann::json::array();
  for (const auto& s : scenes_) scenes.push_back(s.name);
  // d̂ and κ of the obstacles' contact or else the self-contact's: the same.
  const ObstacleContact* contact = statics_ ? statics_->contact() : nullptr;
  const SelfContact* self = statics_ ? statics_->self_contact() : nullptr;
  nlohmann::json contact_json = nullptr;
  if (contact || self)
    contact_json = {{"distance", contact ? contact->distance() : self->distance()},
                    {"stiffness", contact ? contact->stiffness() : self->stiffness()},
                    {"self", self != nullptr}};
  return {{"type", "scene"},
          {"protocol", protocol_version},
          {"scene", scene_name_},
          {"scenes", scenes},
          {"node_count", mesh.node_count()},
          {"triangles", triangles},
          {"grips", grips},
          {"bar", bar},
          {"robot",
           scene.robot ? robot_json(*scene.robot, robot_meshes_) : nlohmann::json(nullptr)},
          {"warnings", mesh_warnings(scene, robot_meshes_)},
          {"obstacles",
           obstacles_json(scene.obstacles, scene.robot ? scene.robot->model.get() : nullptr)},
          {"contact", contact_json},
          {"link", link_ != nullptr},
          {"limits",
           {{"max_message_bytes", max_message_bytes},
            {"max_coordinate", max_coordinate},
            {"max_centerline_points", max_centerline_points},
            {"max_jog_step", options_.max_jog_step}}}};
}

std::string Session::scene_message() const {
  nlohmann::json m = scene_description_;
  nlohmann::json history = nlohmann::json::array();
  for (const auto& h : history_) history.push_back({h.time, h.error_mean, h.editing ? 1 : 0});
  m["history"] = std::move(history);
  return m.dump();
}

std::string Session::state_message(int clients) const {
  const ControllerSnapshot& s = *snapshot_;
  const OnlineCalibrationStatus calibration = calibration_->status();
  nlohmann::json links = nlohmann::json::array();
  for (const auto& T : s.T_world_link) links.push_back(message_pose_json(T));
  const double t = now();
  nlohmann::json m = {
      {"type", "state"},
      {"scene", scene_name_},
      {"seq", s.sequence},
      {"time", t},
      {"controller_time", s.time},
      {"status", to_string(s.status)},
      {"status_reason", s.status_reason},
      {"unreachable", shortfall_names(s.shortfalls)},
      {"tolerance", s.tolerance},
      {"paused", s.paused},
      {"safe", s.safe},
      {"within_limits", s.within_limits},
      {"min_clearance", finite_or_null(s.min_clearance)},
      {"colliding_links", s.colliding_links},
      {"jog_refused_links", s.jog_refused_links},
      {"closest_pair", closest_pair_json(s.closest_pair)},
      {"iterations", s.iterations},
      {"iterations_per_second", finite_or_null(s.iterations_per_second)},
      {"objective", finite_or_null(s.objective)},
      {"error", {{"mean", finite_or_null(s.error.mean)}, {"max", finite_or_null(s.error.max)}}},
      {"editing", t - last_edit_time_ < editing_window},
      {"joints", vector_json(s.joints)},
      {"links", links},
      {"targets", targets_json(s.targets)},
      {"centerline", points_json(s.centerline)},
      {"last_error", s.last_error},
      {"feedback", s.feedback},
      {"observations", s.observations},
      {"observations_ignored", s.observations_ignored},
      {"observation_problem", s.observation_problem},
      {"gate", gate_json(s.gate)},
      {"authority", authority_json(s.authority)},
      {"observations_rejected", observations_rejected_},
      {"observation_rejection", observation_rejection_},
      // null until something was observed: 0 would claim a perfect model and object.
      {"model_error", s.observations ? finite_or_null(s.model_error) : nlohmann::json()},
      {"observed_error", s.observations ? finite_or_null(s.observed_error) : nlohmann::json()},
      {"observed_markers", observed_markers_json(s.observed_markers)},
      {"true_error", world_ ? finite_or_null(true_error_) : nlohmann::json()},
      {"model", model_json(s, controller_->scene())},
      {"calibration", calibration_json(calibration)},
      {"observed_points", points_json(calibration.points)},
      {"clients", clients},
      {"link", link_ ? link_status_json(link_->status()) : nlohmann::json(nullptr)},
      {"measured_links",
       link_ ? measured_links_json(controller_->scene(), link_->status()) : nlohmann::json()}};
  if (!contacts_.is_null()) m["contacts"] = contacts_;  // only with obstacles or self-contact
  return m.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace shapectl::server
