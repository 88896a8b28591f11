#include <shapectl/fem/gradient_gather.hpp>

#include <cassert>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <shapectl/hand_off.hpp>

namespace shapectl {

namespace {
constexpr int kNodeGrain = 256;
}

GradientGather::GradientGather(const ElementNodes& elements, int node_count)
    : corner_offsets_(node_count + 1, 0), corners_(elements.nodes.size()) {
  for (const int node : elements.nodes) ++corner_offsets_[node + 1];
  for (int i = 0; i < node_count; ++i) corner_offsets_[i + 1] += corner_offsets_[i];
  // Corners in ascending order per node: the serial scatter's order.
  std::vector<int> next(corner_offsets_.begin(), corner_offsets_.end() - 1);
  for (std::size_t k = 0; k < elements.nodes.size(); ++k)
    corners_[next[elements.nodes[k]]++] = static_cast<int>(k);
}

void GradientGather::add(const double* per_corner, Eigen::VectorXd& gradient) const {
  const int node_count = static_cast<int>(corner_offsets_.size()) - 1;
  assert(gradient.size() == 3 * node_count);
  HandOff hand_off;
  tbb::parallel_for(tbb::blocked_range<int>(0, node_count, kNodeGrain),
                    hand_off([&](const tbb::blocked_range<int>& range) {
                      for (int i = range.begin(); i != range.end(); ++i) {
                        Vec3 sum = gradient.segment<3>(3 * i);
                        for (int k = corner_offsets_[i]; k < corner_offsets_[i + 1]; ++k)
                          sum += Eigen::Map<const Vec3>(per_corner + 3 * corners_[k]);
                        gradient.segment<3>(3 * i) = sum;
                      }
                    }));
  hand_off.joined();
}

}  // namespace shapectl
