#include <shapectl/control/model_error_feedback.hpp>

#include <algorithm>
#include <cmath>

namespace shapectl {

ModelErrorFeedback::ModelErrorFeedback(std::shared_ptr<const TetMesh> mesh, FeedbackOptions options)
    : mesh_(std::move(mesh)), options_(options) {}

void ModelErrorFeedback::observe(const std::vector<std::pair<int, Vec3>>& observed,
                                 const Positions& predicted) {
  double sum = 0;
  for (const auto& [node, y] : observed) {
    const Vec3 error = y - predicted.segment<3>(3 * node);
    sum += error.squaredNorm();
    Vec3& e = estimate_.try_emplace(node, Vec3::Zero()).first->second;
    e += options_.gain * (error - e);
    const double size = e.norm();
    if (size > options_.max_correction) e *= options_.max_correction / size;
  }
  last_model_error_ = observed.empty() ? 0 : std::sqrt(sum / double(observed.size()));
}

void ModelErrorFeedback::model_changed(const Positions& before, const Positions& after) {
  for (auto& [node, e] : estimate_) {
    e -= after.segment<3>(3 * node) - before.segment<3>(3 * node);
    const double size = e.norm();
    if (size > options_.max_correction) e *= options_.max_correction / size;
  }
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
