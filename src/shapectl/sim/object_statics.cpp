#include <shapectl/sim/object_statics.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <shapectl/robot/kinematics.hpp>
#include <shapectl/sim/contact_obstacles.hpp>

namespace shapectl {

std::string find_unheld_part(const TetMesh& mesh, const std::vector<char>& held) {
  // Union-find over tet connectivity; isolated nodes count as held (they do not move).
  std::vector<int> parent(mesh.node_count());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& t : mesh.tets())
    for (int a = 1; a < 4; ++a) parent[root(t.nodes[a])] = root(t.nodes[0]);
  std::vector<char> part_held(mesh.node_count(), 0);
  for (int i = 0; i < mesh.node_count(); ++i)
    if (held[i]) part_held[root(i)] = 1;
  for (int i : mesh.isolated_nodes()) part_held[root(i)] = 1;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (!part_held[root(i)]) {
      int size = 0;
      for (int k = 0; k < mesh.node_count(); ++k) size += root(k) == root(i);
      return "singular system: nothing holds the object (the part with node " + std::to_string(i) +
             ", " + std::to_string(size) + " nodes, has no fixed or gripped node)";
    }
  return "";
}

RoundoffScale roundoff_scale(const TetMesh& mesh, const Material& material, double weight) {
  // Deformation gradients come from differences of coordinates of magnitude X over edges of
  // length h, so they carry a relative error ~ eps X / h; the stress error is that times the
  // moduli, and a node sums the forces (stress x area ~ h^2) of its ~20 elements. The same
  // error is what the rounding of x̂ itself to doubles leaves in the force. 16 ulps: in a sweep
  // of E and density Newton's quadratic steps go far below it (it does not stall there).
  double h_min = std::numeric_limits<double>::infinity(), h_max = 0;
  for (const auto& t : mesh.tets())
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const double h =
            (mesh.rest_positions()[t.nodes[a]] - mesh.rest_positions()[t.nodes[b]]).norm();
        h_min = std::min(h_min, h);
        h_max = std::max(h_max, h);
      }
  if (mesh.tets().empty()) return {};
  const double X =
      std::max(mesh.bounds_max().cwiseAbs().maxCoeff(), mesh.bounds_min().cwiseAbs().maxCoeff());
  const double moduli = std::abs(material.mu) + std::abs(material.kappa);
  const double eps = std::numeric_limits<double>::epsilon();
  const double extent = (mesh.bounds_max() - mesh.bounds_min()).norm();
  RoundoffScale r;
  r.force = 16 * eps * moduli * h_max * (h_max + X);
  r.energy = 256 * eps *
             (moduli * mesh.total_volume() * (1 + X / h_min) + std::abs(weight) * (X + extent));
  return r;
}

double object_load(const TetMesh& mesh, const Material& material, double weight) {
  const double size = (mesh.bounds_max() - mesh.bounds_min()).norm();
  return weight > 0 ? weight : 1e-3 * material.mu * size * size;
}

namespace {
std::shared_ptr<const TetMesh> placed_mesh(const Scene& scene) {
  std::vector<Vec3> p;
  p.reserve(scene.object_mesh->node_count());
  for (const auto& X : scene.object_mesh->rest_positions()) p.push_back(scene.T_world_object * X);
  std::vector<std::array<int, 4>> tets;
  for (const auto& t : scene.object_mesh->tets()) tets.push_back(t.nodes);
  return std::make_shared<const TetMesh>(std::move(p), std::move(tets), scene.source.string());
}
}  // namespace

namespace {
// Weight plus the applied loads' magnitudes, N: what the force tolerance and the energy's
// round-off scale with (a tip load on a weightless bar is resolved relative to the load).
double applied_load(const Scene& scene, double weight) {
  double load = weight;
  for (const NodeLoad& l : scene.loads) load += l.force.norm();
  return load;
}

// The material of largest moduli, which sets the force round-off (roundoff_scale).
Material stiffest_material(const Scene& scene) {
  Material m = scene.material;
  for (const MaterialRegion& r : scene.regions)
    if (r.material.mu + r.material.kappa > m.mu + m.kappa) m = r.material;
  return m;
}

std::optional<ConstantForce> load_term(const Scene& scene) {
  if (scene.loads.empty()) return std::nullopt;
  return ConstantForce("loads", scene.load_forces());
}

// The barrier on the scene's obstacles: κ as the scene gives it, else scaled to the mean nodal
// load (default_contact_stiffness) so a resting node sits about d̂/2 off a flat obstacle.
double contact_stiffness(const Scene& scene, const TetMesh& placed, double load) {
  return scene.contact.stiffness.value_or(
      default_contact_stiffness(object_load(placed, scene.material, load), placed.node_count(),
                                scene.contact.distance));
}

// Obstacles on links are placed at the reference joints θ⁰ (GrippedObject poses them at each θ).
std::optional<ObstacleContact> contact_term(const Scene& scene, const TetMesh& placed,
                                            double load) {
  std::vector<Obstacle> obstacles = contact_obstacles(scene);
  if (obstacles.empty()) return std::nullopt;
  std::vector<Eigen::Isometry3d> T_world_link;
  if (scene.robot)
    T_world_link =
        forward_kinematics(*scene.robot->model, scene.robot->reference_joints).T_world_link;
  return ObstacleContact(placed, std::move(obstacles), scene.contact.distance,
                         contact_stiffness(scene, placed, load), T_world_link);
}

// The same barrier, κ and d̂ between the object's own surface primitives.
std::optional<SelfContact> self_contact_term(const Scene& scene, const TetMesh& placed,
                                             double load) {
  if (!scene.contact.self) return std::nullopt;
  return SelfContact(placed, scene.contact.distance, contact_stiffness(scene, placed, load));
}

// ε = 1e-4 of the object's diagonal: a sticking contact slips less than that (12 µm for a
// 12 cm block, 0.1 mm for a 1 m cable), small beside any shape the robot is asked for.
constexpr double kSlipPerSize = 1e-4;

FrictionSettings friction_settings(const Scene& scene, const TetMesh& placed, double load) {
  const double size = (placed.bounds_max() - placed.bounds_min()).norm();
  return {.coefficient = scene.obstacles.empty() ? 0.0 : scene.contact.friction,
          .slip = kSlipPerSize * size,
          .load = object_load(placed, scene.material, load),
          .size = size};
}

std::vector<char> fixed_nodes(const Scene& scene, const TetMesh& placed) {
  std::vector<char> fixed(placed.node_count(), 0);
  if (scene.fixed)
    for (int i : scene.fixed->resolve(*scene.object_mesh)) fixed[i] = 1;
  // Nodes no element touches carry no stiffness: keep them where they are.
  for (int i : placed.isolated_nodes()) fixed[i] = 1;
  return fixed;
}

// Krylov steps pay where a factorization is dear: measured (`shapectl bench --sizes 1.5k,12k`,
// docs/benchmarks.md) a third faster target change at 8,019 unknowns, no gain at 1,275, where
// a factorization costs about what assembling the Hessian and the conjugate gradients do.
// With chord steps off they are the only reuse of a nearby factorization: then always.
// (A cold solve's own, exact Krylov steps pay at every size: StaticsOptions::cold_krylov_steps.)
constexpr int kKrylovFrom = 5000;  // unknowns

// `weight`: applied_load's, the weight plus the loads.
StaticsOptions statics_options(const Scene& scene, const TetMesh& placed, double weight) {
  // Converged when every nodal force is a tiny fraction of the weight (or, for a weightless
  // object, of the force that strains it by 0.1 %) — but never below what round-off leaves.
  // Nor that floor above a share of a node's load: where round-off is larger the load cannot be
  // resolved (load_scene refuses such a material), and a scene built in code then ends not
  // converged instead of passing the rest shape as its equilibrium.
  const double load = object_load(placed, scene.material, weight);
  const RoundoffScale roundoff = roundoff_scale(placed, stiffest_material(scene), weight);
  return {.force_tolerance = scene.statics.relative_tolerance * load,
          .force_roundoff =
              std::min(roundoff.force, max_roundoff_share * load / placed.node_count()),
          .energy_roundoff = roundoff.energy,
          .max_iterations = scene.statics.max_iterations,
          .backend = scene.statics.backend,
          .krylov_steps = scene.statics.krylov_steps &&
                          (!scene.statics.chord_steps || 3 * placed.node_count() >= kKrylovFrom),
          .cold_krylov_steps = scene.statics.krylov_steps,
          .chord_steps = scene.statics.chord_steps,
          .rotate_chord = scene.statics.rotate_chord,
          .single_precision_chord = scene.statics.single_precision_chord};
}
}  // namespace

double roundoff_load_ratio(const Scene& scene, const Material& material) {
  const auto placed = placed_mesh(scene);
  const double weight = material.density * scene.gravity.norm() * placed->total_volume();
  return roundoff_scale(*placed, material, weight).force /
         (max_roundoff_share * object_load(*placed, material, weight) / placed->node_count());
}

ObjectStatics::ObjectStatics(const Scene& scene, const std::vector<int>& held_nodes)
    : mesh_(placed_mesh(scene)),
      elasticity_(*mesh_, scene.element_materials()),
      gravity_(*mesh_, elasticity_.materials(), scene.gravity),
      loads_(load_term(scene)),
      contact_(contact_term(scene, *mesh_, applied_load(scene, gravity_.weight()))),
      self_contact_(self_contact_term(scene, *mesh_, applied_load(scene, gravity_.weight()))),
      friction_(friction_settings(scene, *mesh_, applied_load(scene, gravity_.weight()))),
      fixed_node_(fixed_nodes(scene, *mesh_)),
      solver_(mesh_->node_count(), fixed_node_,
              statics_options(scene, *mesh_, applied_load(scene, gravity_.weight()))) {
  std::vector<char> held = fixed_node_;
  for (int i : held_nodes) held[i] = 1;
  if (!contact_) unheld_reason_ = find_unheld_part(*mesh_, held);
}

EnergyTerms ObjectStatics::terms(const EnergyTerm* extra, const ObstacleContact* contact) const {
  EnergyTerms t = {&elasticity_, &gravity_};
  if (loads_) t.push_back(&*loads_);
  if (contact_) t.push_back(contact ? contact : &*contact_);
  if (self_contact_) t.push_back(&*self_contact_);
  if (extra) t.push_back(extra);
  return t;
}

ContactTerms ObjectStatics::contact_terms(double scale, const ObstacleContact* posed) const {
  ContactTerms out;
  if (contact_) out.obstacles = (posed ? *posed : *contact_).scaled(scale);
  if (self_contact_) out.self = self_contact_->scaled(scale);
  return out;
}

EnergyTerms ObjectStatics::terms(const EnergyTerm* extra, const ContactTerms& contact) const {
  EnergyTerms t = {&elasticity_, &gravity_};
  if (loads_) t.push_back(&*loads_);
  if (contact.obstacles) t.push_back(&*contact.obstacles);
  if (contact.self) t.push_back(&*contact.self);
  if (extra) t.push_back(extra);
  return t;
}

Eigen::VectorXd ObjectStatics::load_forces() const {
  return loads_ ? loads_->forces() : Eigen::VectorXd::Zero(3 * mesh_->node_count());
}

StaticsResult ObjectStatics::solve(StaticsWorkspace& ws, Positions& x, const EnergyTerm* extra,
                                   int max_iterations, const StaticsWorkspace* chord,
                                   const StopRequest& stop, const ObstacleContact* posed,
                                   double contact_scale) const {
  const auto refused = [](StaticsStatus status, std::string reason) {
    StaticsResult r;
    r.status = status;
    r.reason = std::move(reason);
    return r;
  };
  if (!unheld_reason_.empty()) return refused(StaticsStatus::Singular, unheld_reason_);
  // The barrier is infinite there: say where instead of "a non-finite energy".
  if (contact_) {
    // With obstacles on links this refuses a warm start a moved obstacle has reached.
    const ObstacleContact& contact = posed ? *posed : *contact_;
    const auto [obstacle, triangle] = contact.first_intersection(x);
    if (obstacle >= 0)
      return refused(StaticsStatus::Inverted,
                     "the starting state touches or intersects obstacle '" +
                         contact.obstacles()[static_cast<std::size_t>(obstacle)].name +
                         "' (object surface triangle " + std::to_string(triangle) +
                         "): no equilibrium sought from there");
  }
  if (self_contact_) {
    const auto [a, b] = self_contact_->first_intersection(x);
    if (a >= 0)
      return refused(StaticsStatus::Inverted,
                     "the starting state touches or intersects itself (object surface triangles " +
                         std::to_string(a) + " and " + std::to_string(b) +
                         "): no equilibrium sought from there");
  }
  const bool with_friction = contact_ && friction_.coefficient > 0;
  const auto solve_at = [&](double scale, Positions& y, const StaticsWorkspace* from) {
    const ContactTerms contact = contact_terms(scale, posed);
    if (with_friction)
      return solve_with_friction(solver_, terms(extra, contact), *contact.obstacles, friction_, ws,
                                 y, max_iterations, from, stop);
    return solver_.solve(terms(extra, contact), ws, y, max_iterations, from, stop);
  };
  if (!contact_ && !self_contact_)
    return solver_.solve(terms(extra), ws, x, max_iterations, chord, stop);
  const double dhat = contact_ ? contact_->distance() : self_contact_->distance();
  return solve_adapting_stiffness(solve_at, contact_terms(1, posed), dhat, contact_scale, ws, x,
                                  chord, with_friction, stop);
}

StaticsResult ObjectStatics::solve(Positions& x, int max_iterations) const {
  StaticsWorkspace ws = make_workspace();
  return solve(ws, x, nullptr, max_iterations);
}

}  // namespace shapectl
