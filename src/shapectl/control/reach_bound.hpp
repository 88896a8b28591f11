#pragma once
// How far the robot can carry the object it grips, bounded from above over every pose: a target
// beyond the bound is refused before optimizing (a file in mm read as metres: "target 529 m
// from ..."), never a target some pose reaches. For each link that grips nodes:
//   base     the origin of the first movable joint on its chain, fixed whatever θ;
//   anchor   |T_link(θ) qᵢ − base| ≤ Σ |joint offsets| after that joint + prismatic travel + |qᵢ|
//            (a revolute joint turns the rest of the chain but does not lengthen it: the
//            triangle inequality joint by joint);
//   node     |x − anchor| ≤ W/K + λ·d: the grip spring stretched by the object's whole weight W,
//            plus the node's rest path length d along mesh edges from the link's gripped nodes,
//            each edge stretched at most λ = 10 times (900 % strain, far past any equilibrium a
//            neo-Hookean model of a real object reaches; the bound is meant to be loose).
// The same sum with the object unstretched (λ = 1) is the reach a best effort names: a target
// beyond it is reached, if at all, only by stretching the object (control/shortfall.hpp).
#include <string>
#include <vector>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/control/targets_file.hpp>
#include <shapectl/sim/gripped_object.hpp>

namespace shapectl {

inline constexpr double max_edge_stretch = 10;  // λ above

struct ArmReach {
  int link = -1;                   // the gripping link
  int base_joint = -1;             // the first movable joint on its chain; -1: the link never moves
  Vec3 base = Vec3::Zero();        // that joint's origin (else the link's), world frame, m
  std::vector<double> node_bound;  // per node: |x − base| ≤ node_bound, m (+inf: no path)
  std::vector<double> rest_bound;  // per node: the same with every edge at its rest length
};

// One per link gripping nodes. +inf bounds when a prismatic joint on the chain has no limits.
std::vector<ArmReach> reach_bounds(const GrippedObject& object);

// Throws InputError "<source>: targets[3]: target 529 m from joint 'j1' (at [..]), the base of
// the arm holding node 12; the robot reaches at most 4.2 m with that node (...)" when a target
// is beyond a bound. Targets as check_targets accepts them.
void check_targets_in_reach(const GrippedObject& object, const ShapeTargets& targets,
                            const std::string& source);
// The target farthest beyond an arm's reach with the object unstretched (rest_bound), in words:
// "node 212's target is 1.10 m from joint 'j1', where the arm gripping with link 'tool' starts:
// 0.24 m beyond the 0.86 m it reaches with that node unstretched (2.4 m stretched tenfold)".
// Empty when every target is within. Depends on the targets alone, never on a pose.
std::string beyond_unstretched_reach(const GrippedObject& object, const ShapeTargets& targets);
// The same for a centre-line's points, against the largest bound of any node (any node may be
// sent to a point): "<source>: centerline[4]: point 529 m from ...".
void check_centerline_in_reach(const GrippedObject& object, const std::vector<Vec3>& centerline,
                               const std::string& source);
// Either, as TARGETS.json (`source`) gives them.
void check_in_reach(const GrippedObject& object, const TargetsInput& input,
                    const std::string& source);

}  // namespace shapectl
