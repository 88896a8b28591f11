#include <shapectl/control/model_error_feedback.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace shapectl {

ModelErrorFeedback::ModelErrorFeedback(std::shared_ptr<const TetMesh> mesh, FeedbackOptions options)
    : mesh_(std::move(mesh)), options_(options) {}

GateVerdict ModelErrorFeedback::observe(const std::vector<std::pair<int, Vec3>>& observed,
                                        const Positions& predicted, double sigma, double time) {
  const GateOptions& gate = options_.gate;
  std::vector<Vec3> errors, innovations;
  std::vector<double> variances;
  for (const auto& [node, y] : observed) {
    errors.push_back(y - predicted.segment<3>(3 * node));
    innovations.push_back(errors.back() - estimate(node));
    const auto it = variance_.find(node);
    variances.push_back(it != variance_.end() ? it->second : gate.prior * gate.prior);
  }
  GateVerdict verdict = judge_innovations(innovations, variances, sigma, gate, gate_counts_);
  if (verdict.frame_rejected) return verdict;
  // The rate is by the clock: a second's worth at most, however long the gap (a pause must not
  // bank authority), nothing for a second frame at the same moment.
  const double seconds = last_time_ ? std::clamp(time - *last_time_, 0.0, 1.0) : 1.0;
  last_time_ = time;
  double sum = 0;
  int used = 0;
  for (std::size_t k = 0; k < observed.size(); ++k) {
    if (!verdict.inside[k]) continue;
    sum += errors[k].squaredNorm(), ++used;
    const int node = observed[k].first;
    Vec3& e = estimate_.try_emplace(node, Vec3::Zero()).first->second;
    move_estimate(e, options_.gain * (errors[k] - e), options_.max_correction_rate * seconds);
    // The filter's variance, propagated (the allowance added first, as the gate assumed).
    const double g = options_.gain, q = gate.model_error_allowance, s = std::min(sigma, q);
    variance_[node] = (1 - g) * (1 - g) * (variances[k] + q * q) + g * g * s * s;
  }
  last_model_error_ = used ? std::sqrt(sum / used) : 0;
  return verdict;
}

void ModelErrorFeedback::move_estimate(Vec3& e, Vec3 step, double rate_budget) {
  if (const double size = step.norm(); size > rate_budget) {
    step *= rate_budget / size;
    ++rate_limited_;
  }
  e += step;
  if (const double size = e.norm(); size > options_.max_correction) {
    e *= options_.max_correction / size;
    ++clamped_;
  }
}

void ModelErrorFeedback::model_changed(const Positions& before, const Positions& after) {
  // Not held to the rate: it keeps x̂ + ê where it was, the model's change is bounded by the
  // calibration's own rules (online_calibration.hpp).
  for (auto& [node, e] : estimate_)
    move_estimate(e, -(after.segment<3>(3 * node) - before.segment<3>(3 * node)),
                  std::numeric_limits<double>::infinity());
}

FeedbackAuthority ModelErrorFeedback::authority() const {
  FeedbackAuthority a{.max_correction = options_.max_correction,
                      .max_correction_rate = options_.max_correction_rate,
                      .rate_limited = rate_limited_,
                      .clamped = clamped_};
  for (const auto& [node, e] : estimate_) a.largest = std::max(a.largest, e.norm());
  return a;
}

Vec3 ModelErrorFeedback::estimate(int node) const {
  if (estimate_.empty()) return Vec3::Zero();
  if (const auto it = estimate_.find(node); it != estimate_.end()) return it->second;
  // Inverse squared distance over the nearest observed nodes, at rest.
  const Vec3& X = mesh_->rest_positions()[node];
  std::vector<std::pair<double, const Vec3*>> nearest;
  for (const auto& [observed, e] : estimate_)
    nearest.emplace_back((mesh_->rest_positions()[observed] - X).squaredNorm(), &e);
  const std::size_t k = std::min<std::size_t>(options_.neighbours, nearest.size());
  std::partial_sort(nearest.begin(), nearest.begin() + k, nearest.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  Vec3 sum = Vec3::Zero();
  double weights = 0;
  for (std::size_t i = 0; i < k; ++i) {
    const double w = 1 / std::max(nearest[i].first, 1e-12);
    sum += w * *nearest[i].second;
    weights += w;
  }
  return sum / weights;
}

ShapeTargets ModelErrorFeedback::corrected(const ShapeTargets& targets) const {
  ShapeTargets out = targets;
  for (int k = 0; k < out.size(); ++k) out.positions[k] -= estimate(out.nodes[k]);
  return out;
}

}  // namespace shapectl
