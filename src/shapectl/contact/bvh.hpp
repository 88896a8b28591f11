#pragma once
// Axis-aligned boxes and a static bounding volume hierarchy over them: the broad phase that
// culls pairs of primitives before their exact distances.
#include <limits>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void extend(const Aabb& b) {
    min = min.cwiseMin(b.min);
    max = max.cwiseMax(b.max);
  }
  Aabb inflated(double r) const { return {(min.array() - r).matrix(), (max.array() + r).matrix()}; }
  bool overlaps(const Aabb& b) const {
    return (min.array() <= b.max.array()).all() && (b.min.array() <= max.array()).all();
  }
};

// Whether segment ab meets `box` (slab test).
bool segment_overlaps(const Vec3& a, const Vec3& b, const Aabb& box);

// A binary tree of boxes, split at the median of the longest axis, built once.
class Bvh {
 public:
  Bvh() = default;
  explicit Bvh(const std::vector<Aabb>& boxes);

  bool empty() const { return nodes_.empty(); }
  // Calls visit(i) for every box i that overlaps `box`. No allocation.
  template <class Visit>
  void query(const Aabb& box, Visit&& visit) const {
    if (nodes_.empty()) return;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!node.box.overlaps(box)) continue;
      if (node.count > 0) {
        for (int k = node.first; k < node.first + node.count; ++k)
          if (boxes_[order_[k]].overlaps(box)) visit(order_[k]);
      } else {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
      }
    }
  }

 private:
  struct Node {
    Aabb box;
    int first = 0;  // leaf: first index into order_; inner node: its first child (two in a row)
    int count = 0;  // leaf: how many boxes; 0 for an inner node
  };
  void build(int index, int begin, int end);

  std::vector<Aabb> boxes_;
  std::vector<int> order_;  // the boxes, leaf by leaf
  std::vector<Node> nodes_;
};

}  // namespace shapectl
