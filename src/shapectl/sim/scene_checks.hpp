#pragma once
// Plausibility checks of a loaded scene, beyond the syntax and ranges load_scene checks: the
// traps that otherwise give a silently wrong result (a reference pose out of limits or in
// collision, grips far from their tools, a mesh drawn in millimetres read as metres).
// Errors where the result would be wrong, warnings where it might be.
#include <string>
#include <vector>

#include <shapectl/sim/scene.hpp>

namespace shapectl {

// Grip region centre (mean of its gripped nodes, placed) to its tool point at the reference
// joints, metres. A grip spring ties each node where it is, so a region the gripper does not
// touch is held by invisible springs; a few millimetres come from where the jaws close.
inline constexpr double grip_warning_distance = 0.02;
inline constexpr double grip_error_distance = 0.05;
// Fewer gripped nodes than this: the object may turn about them (warning).
inline constexpr int grip_warning_node_count = 3;
// Largest object extent (bounding-box diagonal, m): beyond it a mesh was almost surely drawn
// in mm or cm. With a robot also `object_reach_factor` × the extent of its link origins at
// the reference joints (at least 1 m) — the robot could not hold it.
inline constexpr double max_object_extent = 10.0;
inline constexpr double object_reach_factor = 10.0;
// contact.distance (d̂) above this fraction of the object's bounding-box diagonal is refused.
inline constexpr double max_contact_distance_fraction = 0.1;
// An obstacle farther from the object's rest box than distant_obstacle_factor × (the object's
// diagonal + the robot's span), and at least distant_obstacle_floor m, gets a warning.
inline constexpr double distant_obstacle_factor = 3.0;
inline constexpr double distant_obstacle_floor = 2.0;
// Tet count above which the time per target change is worth a warning.
inline constexpr int tet_warning_count = 5000;

// One grip at the reference joints: what every command can report.
struct GripPlacement {
  int node_count = 0;
  double tool_distance = 0;  // region centre to tool point, metres
};
// Per scene.grips entry; the scene must have a robot if it has grips.
std::vector<GripPlacement> grip_placements(const Scene& scene);
// "grips[0] ('left'): 50 nodes, centre 10.0 mm from the tool point", one per grip.
std::vector<std::string> describe_grips(const Scene& scene);

// Time per target change (Gauss–Newton, to < 1 mm) expected for a mesh of `tet_count` tets,
// seconds, through the benchmarks' medians on 2 cores (1,536 tets ~15 ms, 12,288 ~0.2 s,
// 51,714 ~1.4 s).
double expected_seconds_per_target_change(int tet_count);

// Throws InputError naming `source` and origin.field when an object of bounding-box `size`
// (metres) is implausibly large: over max_object_extent, or with a robot (may be null) over
// object_reach_factor × its span. Called before TetGen too, so a mesh in mm fails fast.
void check_object_extent(const std::string& source, const MeshOrigin& origin, const Vec3& size,
                         const RobotSetup* robot);

// Throws InputError naming scene.source and the field (robot.reference_joints.<joint>,
// grips[i], object.mesh) where the result would be wrong; returns warnings
// ("<file>: <field>: ...") where it might be. Scenes built in code can be checked the same way.
std::vector<std::string> check_scene(const Scene& scene);

}  // namespace shapectl
