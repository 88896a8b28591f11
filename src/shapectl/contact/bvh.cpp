#include <shapectl/contact/bvh.hpp>

#include <algorithm>
#include <numeric>

namespace shapectl {

namespace {
constexpr int kLeafSize = 4;
}

bool segment_overlaps(const Vec3& a, const Vec3& b, const Aabb& box) {
  // The parameter interval [t0, t1] of the segment inside each slab, intersected.
  double t0 = 0, t1 = 1;
  const Vec3 d = b - a;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (a[k] < box.min[k] || a[k] > box.max[k]) return false;
      continue;
    }
    double near = (box.min[k] - a[k]) / d[k], far = (box.max[k] - a[k]) / d[k];
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
    if (t0 > t1) return false;
  }
  return true;
}

Bvh::Bvh(const std::vector<Aabb>& boxes) : boxes_(boxes), order_(boxes.size()) {
  if (boxes.empty()) return;
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * boxes.size() / kLeafSize + 2);
  nodes_.emplace_back();
  build(0, 0, static_cast<int>(boxes.size()));
}

// Fills node `index` for order_[begin … end). Median splits: depth ≤ log2(n) + 1, so the
// query's fixed stack of 64 suffices for any count that fits in memory.
void Bvh::build(int index, int begin, int end) {
  Aabb box, centres;
  for (int k = begin; k < end; ++k) {
    box.extend(boxes_[order_[k]]);
    centres.extend(0.5 * (boxes_[order_[k]].min + boxes_[order_[k]].max));
  }
  nodes_[index].box = box;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return;
  }
  int axis = 0;
  (centres.max - centres.min).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int i, int j) {
                     return boxes_[i].min[axis] + boxes_[i].max[axis] <
                            boxes_[j].min[axis] + boxes_[j].max[axis];
                   });
  const int left = static_cast<int>(nodes_.size());
  nodes_[index].first = left;
  nodes_[index].count = 0;
  nodes_.emplace_back();
  nodes_.emplace_back();
  build(left, begin, middle);
  build(left + 1, middle, end);
}

}  // namespace shapectl
