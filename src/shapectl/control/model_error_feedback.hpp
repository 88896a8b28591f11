#pragma once
// Model-error feedback: what makes the *observed* object reach the targets although the model
// is not exact. The model error e(θ) = y(θ) − x̂(θ) (observed minus predicted, at the joints
// the observation was taken at) is estimated at the observed nodes and low-pass filtered,
//   ê ← ê + gain · (e − ê),
// and the optimizer aims the model at t − ê instead of t. At a fixed point ê = e(θ*), so
// y(θ*) = x̂(θ*) + e(θ*) = t − ê + ê = t. Nodes without an observation take the inverse-
// distance-weighted estimate of the nearest observed nodes (rest positions).
//
// It converges while e changes slowly with θ compared with how far the corrected targets move θ
// (a contraction): a model within tens of percent of the real stiffness, grips off by
// millimetres. It changes only targets, never joints: the optimizer's collision and joint-
// limit barriers and the link's motion governor bound whatever it asks for. Its authority is
// bounded: each node's correction is clamped to `max_correction` in total and may change by at
// most `max_correction_rate` per second of the controller's clock (not per observation: a flood
// of frames gains nothing), so no sequence of observations can move a target farther or faster.
// Markers are gated first (control/observation_gate.hpp).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <shapectl/control/observation_gate.hpp>
#include <shapectl/control/shape_targets.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

struct FeedbackOptions {
  // Per observation, in (0, 1]: the estimate's noise is σ·√(g/(2−g)) (0.33σ at 0.2), and it
  // settles in ~1/g observations (5 at 0.2: half a second at a camera's 10 Hz).
  double gain = 0.2;
  // The optimizer is re-aimed only when the corrected targets move (RMS) by more than this
  // (m), or by more than twice the estimate's noise at the observations' σ: noise must not
  // keep the robot chasing.
  double retarget_threshold = 0.0002;
  // Authority, per node: the largest correction (m) and how fast it may change (m/s). A
  // model within tens of percent and grips off by millimetres err by ~20 mm (the closed-loop
  // tests' world: 17-20 mm); that loop never had an update held to this rate.
  double max_correction = 0.03;
  double max_correction_rate = 0.02;
  int neighbours = 4;  // observed nodes an unobserved node's estimate comes from
  GateOptions gate = {};
};

// The feedback's authority now: its bounds, the largest correction it applies (m) and how often
// an update was held to a bound.
struct FeedbackAuthority {
  double max_correction = 0;       // m
  double max_correction_rate = 0;  // m/s
  double largest = 0;              // m, max |ê| over the observed nodes
  std::uint64_t rate_limited = 0;  // node updates held to the rate
  std::uint64_t clamped = 0;       // node updates held to max_correction
  // The controller's trust region (ControllerOptions::trust_region), rad per joint, and how far
  // the joints are now from where the loop started (0 while the optimizer walks for the user).
  double trust_region = 0;
  double joint_offset = 0;
};

class ModelErrorFeedback {
 public:
  explicit ModelErrorFeedback(std::shared_ptr<const TetMesh> mesh, FeedbackOptions options = {});

  // One observation: node → observed position (world), the model's equilibrium at the joints
  // the observation was taken at, the frame's noise σ (m) and the time it is taken in (s, the
  // controller's clock: never the observer's stamp, which a lying observer sets). Markers
  // outside the gate are left out; a rejected frame changes nothing but the counts.
  GateVerdict observe(const std::vector<std::pair<int, Vec3>>& observed, const Positions& predicted,
                      double sigma, double time);
  // The model changed (a new calibration): the prediction at the last observation's joints
  // moved from `before` to `after`. The estimate follows, ê ← ê − (after − before) at the
  // observed nodes, so that x̂ + ê, the shape the loop believes the object has, stays the same
  // and the corrected targets move with the model instead of jumping.
  void model_changed(const Positions& before, const Positions& after);
  // The targets the optimizer should aim the model at.
  ShapeTargets corrected(const ShapeTargets& targets) const;
  // The current estimate at `node` (zero before any observation).
  Vec3 estimate(int node) const;
  // RMS of the last observation's model error |e| over its nodes, m.
  double last_model_error() const { return last_model_error_; }
  const GateCounts& gate_counts() const { return gate_counts_; }
  FeedbackAuthority authority() const;
  // Forgets the estimate (the counts stay: they say what happened in the session).
  void reset() { estimate_.clear(), variance_.clear(), last_model_error_ = 0, last_time_.reset(); }

 private:
  // ê ← ê + step, the step held to `rate_budget` (m) and the result to max_correction.
  void move_estimate(Vec3& e, Vec3 step, double rate_budget);

  std::shared_ptr<const TetMesh> mesh_;
  FeedbackOptions options_;
  std::map<int, Vec3> estimate_;    // ê at the observed nodes
  std::map<int, double> variance_;  // its variance per axis (m²), for the gate
  double last_model_error_ = 0;
  std::optional<double> last_time_;  // of the last accepted observation, s
  GateCounts gate_counts_;
  std::uint64_t rate_limited_ = 0, clamped_ = 0;
};

}  // namespace shapectl
