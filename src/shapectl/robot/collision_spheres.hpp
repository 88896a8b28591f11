#pragma once
// Self-collision of a robot approximated by spheres fixed on its links.
// Constraint per checked sphere pair: |s_i − s_j| ≥ r_i + r_j + margin, made soft with a
// CubicBarrier on the violation v = r_i + r_j + margin − |s_i − s_j| (metres).
//
// Checked pairs: spheres on two links that move relative to each other and are not adjacent,
// i.e. not in the same rigid group (links joined by fixed joints) nor in groups joined by one
// movable joint, and not in the ignore list.
//
// JSON (one file per robot, beside its URDF):
//   {"description": "...",              optional, free text
//    "margin": 0.005,                   optional, metres, default 0
//    "stiffness": 1e6,                  optional, k of the barrier, default 1e6
//    "spheres": {"link": [{"center": [x, y, z], "radius": r}, ...], ...},   link frame, metres
//    "ignore_pairs": [["link_a", "link_b"], ...]}                          optional
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <shapectl/robot/cubic_barrier.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl {

class JsonInput;

struct CollisionSphere {
  int link = -1;
  Vec3 center_link = Vec3::Zero();  // in the link frame, metres
  double radius = 0;                // metres
};

struct SphereClearance {
  int first = -1;  // sphere indices
  int second = -1;
  double clearance = 0;  // |s_i − s_j| − r_i − r_j, metres; negative when the spheres overlap
};

class CollisionModel {
 public:
  static constexpr double default_stiffness = 1e6;

  static CollisionModel load_json_file(const RobotModel& robot, const std::filesystem::path& file);
  static CollisionModel from_json(const RobotModel& robot, const JsonInput& json);
  // `ignore_pairs` are link index pairs never checked.
  CollisionModel(const RobotModel& robot, std::vector<CollisionSphere> spheres, double margin,
                 double stiffness, const std::vector<std::pair<int, int>>& ignore_pairs = {});

  // Grouped by link, in link order (a stable sort of the input).
  const std::vector<CollisionSphere>& spheres() const { return spheres_; }
  // Checked pairs, as sphere indices.
  const std::vector<std::pair<int, int>>& pairs() const { return pairs_; }
  int pair_count() const { return static_cast<int>(pairs_.size()); }
  double margin() const { return margin_; }
  double stiffness() const { return barrier_.stiffness; }

  // Sphere centres in the world frame (resized to spheres().size()).
  void sphere_centers(const KinematicsState& state, std::vector<Vec3>& centers) const;
  // Smallest clearance over all checked pairs (margin not subtracted); +inf without pairs.
  double min_clearance(const KinematicsState& state) const;
  // The `count` checked pairs with the smallest clearance, smallest first.
  std::vector<SphereClearance> closest_pairs(const KinematicsState& state, std::size_t count) const;

  // Σ barriers; `gradient` w.r.t. the active joints (size robot.active_count(), overwritten)
  // may be null. `robot` must be the model the spheres were built for.
  double value(const RobotModel& robot, const KinematicsState& state,
               Eigen::VectorXd* gradient = nullptr) const;
  // One residual per checked pair (zero when satisfied), ½|r|² = value; `jacobian`
  // (pair_count × active_count, overwritten) may be null.
  void residuals(const RobotModel& robot, const KinematicsState& state, Eigen::VectorXd& r,
                 Eigen::MatrixXd* jacobian = nullptr) const;

 private:
  // One sphere against the contiguous spheres [begin, end) of another link: the hot loop runs
  // over such blocks with the centres stored coordinate by coordinate.
  struct Block {
    int sphere;
    int begin;
    int end;
  };
  std::vector<CollisionSphere> spheres_;
  std::vector<std::pair<int, int>> pairs_;  // the blocks' pairs, in block order
  std::vector<Block> blocks_;
  std::vector<double> radii_;
  std::vector<double> reach_;  // per pair: r_i + r_j + margin
  double margin_;
  CubicBarrier barrier_;
};

}  // namespace shapectl
