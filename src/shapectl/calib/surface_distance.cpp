#include <shapectl/calib/surface_distance.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace shapectl {

namespace {

constexpr int max_leaf_triangles = 4;

Vec3 point_at(const Eigen::Vector3d& barycentric, const std::array<Vec3, 3>& corner) {
  return barycentric[0] * corner[0] + barycentric[1] * corner[1] + barycentric[2] * corner[2];
}

// The closest point of the triangle's boundary: the vertex and edge regions.
Eigen::Vector3d closest_on_edges(const Vec3& p, const std::array<Vec3, 3>& corner) {
  Eigen::Vector3d best = Eigen::Vector3d::UnitX();
  double best_squared = (p - corner[0]).squaredNorm();
  for (int k = 0; k < 3; ++k) {
    const Vec3& u = corner[k];
    const Vec3 edge = corner[(k + 1) % 3] - u;
    const double length_squared = edge.squaredNorm();
    const double t =
        length_squared > 0 ? std::clamp((p - u).dot(edge) / length_squared, 0.0, 1.0) : 0.0;
    const double squared = (p - (u + t * edge)).squaredNorm();
    if (squared < best_squared) {
      best_squared = squared;
      best.setZero();
      best[k] = 1 - t;
      best[(k + 1) % 3] = t;
    }
  }
  return best;
}

}  // namespace

Eigen::Vector3d closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const std::array<Vec3, 3> corner{a, b, c};
  const Vec3 normal = (b - a).cross(c - a);
  const double area_squared = normal.squaredNorm();  // (2 · area)²
  if (area_squared > 0) {
    // Barycentric coordinates of p's projection onto the plane, as signed sub-areas (p's
    // offset along the normal cancels). All >= 0: the face region, the projection is closest.
    const double u = normal.dot((b - p).cross(c - p)) / area_squared;
    const double v = normal.dot((c - p).cross(a - p)) / area_squared;
    const Eigen::Vector3d face(u, v, 1 - u - v);
    if (face.minCoeff() >= 0) {
      // A sliver (twice its area below 1e-6 of its longest edge squared) has inexact
      // sub-areas: then take the closer of this point on it and the closest of its edges.
      const double longest =
          std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
      if (area_squared > 1e-12 * longest * longest) return face;
      const Eigen::Vector3d edges = closest_on_edges(p, corner);
      return (p - point_at(face, corner)).squaredNorm() <
                     (p - point_at(edges, corner)).squaredNorm()
                 ? face
                 : edges;
    }
  }
  // Outside the face region, or collinear or coincident corners: the boundary.
  return closest_on_edges(p, corner);
}

double SurfaceDistance::Box::squared_distance(const Vec3& p) const {
  return (min - p).cwiseMax(p - max).cwiseMax(0.0).squaredNorm();
}

SurfaceDistance::SurfaceDistance(std::vector<std::array<int, 3>> triangles)
    : triangles_(std::move(triangles)) {
  if (triangles_.empty()) throw std::invalid_argument("SurfaceDistance: no triangles");
  for (const auto& t : triangles_)
    if (std::min({t[0], t[1], t[2]}) < 0)
      throw std::invalid_argument("SurfaceDistance: negative node index");
}

void SurfaceDistance::update(const Positions& x) {
  int max_node = 0;
  for (const auto& t : triangles_) max_node = std::max({max_node, t[0], t[1], t[2]});
  if (x.size() % 3 != 0 || x.size() / 3 <= max_node || !x.allFinite())
    throw std::invalid_argument("SurfaceDistance::update: " + std::to_string(x.size()) +
                                " finite coordinates expected for nodes up to " +
                                std::to_string(max_node));
  const int count = static_cast<int>(triangles_.size());
  corners_.resize(triangles_.size());
  std::vector<Vec3> centroids(triangles_.size());
  for (int t = 0; t < count; ++t) {
    for (int k = 0; k < 3; ++k) corners_[t][k] = x.segment<3>(3 * triangles_[t][k]);
    centroids[t] = (corners_[t][0] + corners_[t][1] + corners_[t][2]) / 3;
  }
  order_.resize(triangles_.size());
  std::iota(order_.begin(), order_.end(), 0);

  // Top down, with a work list instead of recursion: each node splits its triangles at the
  // median centroid along its widest axis, so the depth is at most log2(count) + 1.
  tree_.assign(1, TreeNode{});
  struct Pending {
    int node, begin, end;
  };
  std::vector<Pending> pending{{0, 0, count}};
  while (!pending.empty()) {
    const Pending job = pending.back();
    pending.pop_back();
    Box box{Vec3::Constant(std::numeric_limits<double>::infinity()),
            Vec3::Constant(-std::numeric_limits<double>::infinity())};
    Box centres = box;
    for (int i = job.begin; i < job.end; ++i) {
      for (const Vec3& corner : corners_[order_[i]]) {
        box.min = box.min.cwiseMin(corner);
        box.max = box.max.cwiseMax(corner);
      }
      centres.min = centres.min.cwiseMin(centroids[order_[i]]);
      centres.max = centres.max.cwiseMax(centroids[order_[i]]);
    }
    tree_[job.node].box = box;
    if (job.end - job.begin <= max_leaf_triangles) {
      tree_[job.node].first = job.begin;
      tree_[job.node].count = job.end - job.begin;
      continue;
    }
    int axis = 0;
    (centres.max - centres.min).maxCoeff(&axis);
    const int middle = (job.begin + job.end) / 2;
    std::nth_element(order_.begin() + job.begin, order_.begin() + middle, order_.begin() + job.end,
                     [&](int s, int t) { return centroids[s][axis] < centroids[t][axis]; });
    const int child = static_cast<int>(tree_.size());
    tree_[job.node].first = child;
    tree_[job.node].count = 0;
    tree_.resize(tree_.size() + 2);
    pending.push_back({child, job.begin, middle});
    pending.push_back({child + 1, middle, job.end});
  }
}

SurfaceHit SurfaceDistance::closest(const Vec3& p) const {
  if (tree_.empty()) throw std::logic_error("SurfaceDistance::closest before update");
  if (!p.allFinite()) throw std::invalid_argument("SurfaceDistance::closest: a non-finite point");
  SurfaceHit hit;
  double best = std::numeric_limits<double>::infinity();  // squared distance
  // Depth-first, nearer child first, skipping boxes no closer than the best so far. The stack
  // holds at most one entry per level plus one: the depth is below 64 for any int count.
  std::array<int, 64> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const TreeNode& node = tree_[stack[--top]];
    if (node.box.squared_distance(p) >= best) continue;
    if (node.count == 0) {
      const double near_first = tree_[node.first].box.squared_distance(p);
      const double near_second = tree_[node.first + 1].box.squared_distance(p);
      assert(top + 2 <= static_cast<int>(stack.size()));
      // Pushed last, visited first.
      stack[top++] = near_first <= near_second ? node.first + 1 : node.first;
      stack[top++] = near_first <= near_second ? node.first : node.first + 1;
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      const int t = order_[i];
      const auto& corner = corners_[t];
      const Eigen::Vector3d b = closest_on_triangle(p, corner[0], corner[1], corner[2]);
      const Vec3 point = point_at(b, corner);
      const double squared = (p - point).squaredNorm();
      if (squared < best) {
        best = squared;
        hit = {t, triangles_[t], b, point, 0};
      }
    }
  }
  hit.distance = std::sqrt(best);
  return hit;
}

}  // namespace shapectl
