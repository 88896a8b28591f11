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
// limit barriers and the link's motion governor bound whatever it asks for, and a correction is
// clamped to `max_correction` so a wrong observation cannot drag the targets away.
#include <map>
#include <memory>
#include <vector>

#include <shapectl/control/shape_targets.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

struct FeedbackOptions {
  // Per observation, in (0, 1]: the estimate's noise is σ·√(g/(2−g)) (0.33σ at 0.2), and it
  // settles in ~1/g observations (5 at 0.2: half a second at a camera's 10 Hz).
  double gain = 0.2;
  // The optimizer is re-aimed only when a corrected target moves by more than this (m): noise
  // must not keep the robot chasing.
  double retarget_threshold = 0.0002;
  double max_correction = 0.05;  // m, per node
  int neighbours = 4;            // observed nodes an unobserved node's estimate comes from
};

class ModelErrorFeedback {
 public:
  explicit ModelErrorFeedback(std::shared_ptr<const TetMesh> mesh, FeedbackOptions options = {});

  // One observation: node → observed position (world), and the model's equilibrium at the joints
  // the observation was taken at.
  void observe(const std::vector<std::pair<int, Vec3>>& observed, const Positions& predicted);
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
  void reset() { estimate_.clear(), last_model_error_ = 0; }

 private:
  std::shared_ptr<const TetMesh> mesh_;
  FeedbackOptions options_;
  std::map<int, Vec3> estimate_;  // ê at the observed nodes
  double last_model_error_ = 0;
};

}  // namespace shapectl
