#pragma once
// A plausibility gate on observed markers, before they may correct anything: the innovation
// ν = e − ê of a marker (its model error e = observed − predicted at the observation's joints,
// minus the error the feedback already believes there) is tested against its variance,
//   |ν|² / (P + q² + σ²) ≤ χ²₃(0.999) = 16.27,
// P the variance of the node's estimate ê (per axis: `prior`² before the node was seen, then
// as the filter ê ← ê + g(e − ê) propagates it, P ← (1−g)²(P + q²) + g²σ²), q the model-error
// allowance (how far the true model error may move between observations: the robot moved, a
// new target), σ the frame's noise, counted up to q (a frame cannot widen the gate by claiming
// more). So the gate is wide for a node not yet seen (a model off by centimetres must be
// correctable: 123 mm) and settles at 40 mm once the estimate has (defaults, σ ≪ q). It does not
// widen with the innovations it sees: an attacker feeding slowly growing lies could walk such a
// gate without bound; what a lie inside the gate can do is bounded by the feedback's authority
// (model_error_feedback.hpp). A frame with more than half of its markers outside is rejected
// whole: wrong joints or a camera that lost its registration, its other markers suspect too.
#include <cstdint>
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct GateOptions {
  double model_error_allowance = 0.006;  // q, m (1 standard deviation per axis)
  double prior = 0.03;                   // m, 1 standard deviation per axis of an unseen node's ê
  double chi_squared = 16.27;            // χ² with 3 degrees of freedom at 0.999
};

// What the gate has seen, counted per reason.
struct GateCounts {
  std::uint64_t markers_checked = 0;
  std::uint64_t markers_rejected = 0;  // innovation outside the gate
  std::uint64_t frames_checked = 0;
  std::uint64_t frames_rejected = 0;  // more than half of the markers outside
};

struct GateVerdict {
  std::vector<bool> inside;  // per marker
  bool frame_rejected = false;
  double radius = 0;   // m: the widest of the frame's gates
  double largest = 0;  // m: the largest |ν| seen in it (+inf for a non-finite one)
  std::string reason;  // empty when every marker is inside
};

// The gate's radius (m) for a marker whose estimate has variance `variance` (m², per axis) in
// a frame of noise `sigma` (m): √(χ² (P + q² + min(σ, q)²)).
double gate_radius(double variance, double sigma, const GateOptions& options);
// Judges one frame's innovations (m, world frame), each with its estimate's variance, and adds
// them to `counts`.
GateVerdict judge_innovations(const std::vector<Vec3>& innovations,
                              const std::vector<double>& variances, double sigma,
                              const GateOptions& options, GateCounts& counts);

}  // namespace shapectl
