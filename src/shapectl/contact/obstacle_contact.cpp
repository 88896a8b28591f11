#include <shapectl/contact/obstacle_contact.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <shapectl/contact/barrier.hpp>
#include <shapectl/contact/bvh.hpp>
#include <shapectl/contact/point_point_distance.hpp>
#include <shapectl/contact/point_segment_distance.hpp>
#include <shapectl/contact/point_triangle_distance.hpp>
#include <shapectl/contact/segment_segment_distance.hpp>
#include <shapectl/contact/segment_triangle_distance.hpp>
#include <shapectl/contact/triangle_edges.hpp>

namespace shapectl {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The kinds of pairs; the first four couple one object vertex, SegmentEdge an object edge,
// PointTriangle an object triangle.
enum class PairKind : unsigned char {
  VertexHalfSpace,
  VertexTriangle,
  VertexSegment,
  VertexPoint,
  SegmentEdge,    // obstacle segment – object edge
  PointTriangle,  // obstacle point – object triangle
};

struct Pair {
  PairKind kind;
  int object;  // index into the surface's vertices, edges or triangles
  int other;   // index into Impl's planes, triangles, segments or points
};

// Object nodes a pair couples: 1, 2 or 3.
constexpr int arity(PairKind kind) {
  return kind == PairKind::SegmentEdge ? 2 : kind == PairKind::PointTriangle ? 3 : 1;
}

struct Plane {
  int obstacle;
  HalfSpace h;
};
struct Triangle {
  int obstacle;
  Vec3 a, b, c;
  double radius;
};
struct Segment {
  int obstacle;
  Vec3 a, b;
  double radius;
};
struct Point {
  int obstacle;
  Vec3 p;
  double radius;
};

Vec3 node(const Positions& x, int i) { return x.segment<3>(3 * i); }

}  // namespace

struct ObstacleContact::Impl {
  // The object's surface.
  std::vector<int> vertices;
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> triangles;
  // The obstacles' primitives, and the hierarchies each kind of object primitive searches.
  std::vector<Plane> planes;
  std::vector<Triangle> obstacle_triangles;
  std::vector<Segment> segments;                    // every segment: against object edges
  std::vector<Point> points;                        // every point: against object triangles
  std::vector<int> vertex_segments, vertex_points;  // those an object vertex meets directly
  Bvh triangle_bvh, segment_bvh, point_bvh, vertex_segment_bvh, vertex_point_bvh;

  int element(const Pair& p) const {
    switch (arity(p.kind)) {
      case 1: return p.object;
      case 2: return static_cast<int>(vertices.size()) + p.object;
      default: return static_cast<int>(vertices.size() + edges.size()) + p.object;
    }
  }

  template <int K>
  std::array<int, K> nodes(const Pair& p) const {
    if constexpr (K == 1) return {vertices[p.object]};
    if constexpr (K == 2) return edges[p.object];
    if constexpr (K == 3) return triangles[p.object];
  }

  int obstacle(const Pair& p) const {
    switch (p.kind) {
      case PairKind::VertexHalfSpace: return planes[p.other].obstacle;
      case PairKind::VertexTriangle: return obstacle_triangles[p.other].obstacle;
      case PairKind::VertexSegment:
      case PairKind::SegmentEdge: return segments[p.other].obstacle;
      default: return points[p.other].obstacle;
    }
  }

  // The gap d of pair p with its object nodes at `at`; its gradient and Hessian with respect to
  // their coordinates if asked (may be null).
  template <int K>
  double gap(const Pair& p, const std::array<Vec3, K>& at, VecN<3 * K>* g, MatN<3 * K>* h) const {
    constexpr int N = 3 * K;
    if constexpr (K == 1) {
      switch (p.kind) {
        case PairKind::VertexHalfSpace: {
          const HalfSpace& s = planes[p.other].h;
          if (g) *g = s.normal;
          if (h) h->setZero();
          return (at[0] - s.point).dot(s.normal);
        }
        case PairKind::VertexTriangle: {
          const Triangle& t = obstacle_triangles[p.other];
          return point_triangle_distance<N>(at[0], t.a, t.b, t.c, {true, false, false, false}, g,
                                            h) -
                 t.radius;
        }
        case PairKind::VertexSegment: {
          const Segment& s = segments[p.other];
          return point_segment_distance<N>(at[0], s.a, s.b, {true, false, false}, g, h) - s.radius;
        }
        default: {
          const Point& q = points[p.other];
          return point_point_distance<N>(at[0], q.p, {true, false}, g, h) - q.radius;
        }
      }
    } else if constexpr (K == 2) {
      const Segment& s = segments[p.other];
      return segment_segment_distance<N>(at[0], at[1], s.a, s.b, {true, true, false, false}, g, h) -
             s.radius;
    } else {
      const Point& q = points[p.other];
      return point_triangle_distance<N>(q.p, at[0], at[1], at[2], {false, true, true, true}, g, h) -
             q.radius;
    }
  }

  template <int K>
  std::array<Vec3, K> positions(const Pair& p, const Positions& x) const {
    const std::array<int, K> n = nodes<K>(p);
    std::array<Vec3, K> at;
    for (int k = 0; k < K; ++k) at[k] = node(x, n[k]);
    return at;
  }

  // Calls visit(pair) for every pair whose boxes overlap: the object primitive's box at x
  // (swept to x + dx if dx is not null) inflated by `inflate`, the obstacle primitive's by its
  // radius. Half-spaces: every vertex whose gap is below `inflate` at x or x + dx.
  template <class Visit>
  void for_each_candidate(const Positions& x, const Eigen::VectorXd* dx, double inflate,
                          Visit&& visit) const {
    const auto box_of = [&](std::initializer_list<int> ns) {
      Aabb box;
      for (int n : ns) {
        box.extend(node(x, n));
        if (dx) box.extend(node(x, n) + dx->segment<3>(3 * n));
      }
      return box.inflated(inflate);
    };
    const bool vertex_searches =
        !triangle_bvh.empty() || !vertex_segment_bvh.empty() || !vertex_point_bvh.empty();
    for (int v = 0; v < static_cast<int>(vertices.size()); ++v) {
      const Vec3 p = node(x, vertices[v]);
      for (int s = 0; s < static_cast<int>(planes.size()); ++s) {
        const HalfSpace& h = planes[s].h;
        double gap = (p - h.point).dot(h.normal);
        if (dx) gap = std::min(gap, gap + dx->segment<3>(3 * vertices[v]).dot(h.normal));
        if (gap < inflate) visit(Pair{PairKind::VertexHalfSpace, v, s});
      }
      if (!vertex_searches) continue;
      const Aabb box = box_of({vertices[v]});
      triangle_bvh.query(box, [&](int i) { visit(Pair{PairKind::VertexTriangle, v, i}); });
      vertex_segment_bvh.query(box, [&](int i) {
        visit(Pair{PairKind::VertexSegment, v, vertex_segments[i]});
      });
      vertex_point_bvh.query(box, [&](int i) {
        visit(Pair{PairKind::VertexPoint, v, vertex_points[i]});
      });
    }
    if (!segment_bvh.empty())
      for (int e = 0; e < static_cast<int>(edges.size()); ++e)
        segment_bvh.query(box_of({edges[e][0], edges[e][1]}), [&](int i) {
          visit(Pair{PairKind::SegmentEdge, e, i});
        });
    if (!point_bvh.empty())
      for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
        const auto& tri = triangles[t];
        point_bvh.query(box_of({tri[0], tri[1], tri[2]}), [&](int i) {
          visit(Pair{PairKind::PointTriangle, t, i});
        });
      }
  }
};

namespace {

// f(std::integral_constant<int, K>) with K the pair's node count.
template <class F>
decltype(auto) with_arity(PairKind kind, F&& f) {
  switch (arity(kind)) {
    case 1: return f(std::integral_constant<int, 1>());
    case 2: return f(std::integral_constant<int, 2>());
    default: return f(std::integral_constant<int, 3>());
  }
}

template <int N>
void clamp_negative_eigenvalues(MatN<N>& H) {
  Eigen::SelfAdjointEigenSolver<MatN<N>> eig(H);
  H = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
      eig.eigenvectors().transpose();
}

Aabb box_of(std::initializer_list<Vec3> points, double radius) {
  Aabb box;
  for (const Vec3& p : points) box.extend(p);
  return box.inflated(radius);
}

}  // namespace

ObstacleContact::ObstacleContact(const TetMesh& mesh, std::vector<Obstacle> obstacles,
                                 double distance, double stiffness)
    : obstacles_(std::move(obstacles)), distance_(distance), stiffness_(stiffness) {
  if (!(distance > 0) || !std::isfinite(distance))
    throw std::invalid_argument("ObstacleContact: distance must be positive and finite");
  if (!(stiffness >= 0) || !std::isfinite(stiffness))
    throw std::invalid_argument("ObstacleContact: stiffness must be non-negative and finite");
  auto m = std::make_shared<Impl>();
  m->triangles = mesh.surface_triangles();
  m->edges = triangle_edges(m->triangles);
  for (const auto& t : m->triangles) m->vertices.insert(m->vertices.end(), t.begin(), t.end());
  std::sort(m->vertices.begin(), m->vertices.end());
  m->vertices.erase(std::unique(m->vertices.begin(), m->vertices.end()), m->vertices.end());

  std::vector<Aabb> triangle_boxes, segment_boxes, point_boxes, vertex_segment_boxes,
      vertex_point_boxes;
  for (int o = 0; o < static_cast<int>(obstacles_.size()); ++o) {
    const Obstacle& ob = obstacles_[o];
    const double r = ob.radius;
    if (ob.plane) m->planes.push_back({o, *ob.plane});
    for (const auto& t : ob.triangles) {
      m->obstacle_triangles.push_back({o, ob.points[t[0]], ob.points[t[1]], ob.points[t[2]], r});
      triangle_boxes.push_back(box_of({ob.points[t[0]], ob.points[t[1]], ob.points[t[2]]}, r));
    }
    // An object vertex meets a triangle's edges and corners through the point–triangle
    // distance, a segment's ends through the point–segment distance.
    for (const auto& e : ob.edges) {
      if (ob.triangles.empty()) {
        m->vertex_segments.push_back(static_cast<int>(m->segments.size()));
        vertex_segment_boxes.push_back(box_of({ob.points[e[0]], ob.points[e[1]]}, r));
      }
      m->segments.push_back({o, ob.points[e[0]], ob.points[e[1]], r});
      segment_boxes.push_back(box_of({ob.points[e[0]], ob.points[e[1]]}, r));
    }
    for (const Vec3& p : ob.points) {
      if (ob.triangles.empty() && ob.edges.empty()) {
        m->vertex_points.push_back(static_cast<int>(m->points.size()));
        vertex_point_boxes.push_back(box_of({p}, r));
      }
      m->points.push_back({o, p, r});
      point_boxes.push_back(box_of({p}, r));
    }
  }
  m->triangle_bvh = Bvh(triangle_boxes);
  m->segment_bvh = Bvh(segment_boxes);
  m->point_bvh = Bvh(point_boxes);
  m->vertex_segment_bvh = Bvh(vertex_segment_boxes);
  m->vertex_point_bvh = Bvh(vertex_point_boxes);
  impl_ = std::move(m);
}

double ObstacleContact::value(const Positions& x) const {
  const Impl& m = *impl_;
  double sum = 0;
  bool intersecting = false;
  m.for_each_candidate(x, nullptr, distance_, [&](const Pair& p) {
    const double d = with_arity(p.kind, [&](auto k) {
      constexpr int K = decltype(k)::value;
      return m.gap<K>(p, m.positions<K>(p, x), nullptr, nullptr);
    });
    if (d < distance_) {
      if (!(d > 0)) intersecting = true;
      else sum += barrier(d, distance_).value;
    }
  });
  return intersecting ? kInf : stiffness_ * sum;
}

void ObstacleContact::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const Impl& m = *impl_;
  m.for_each_candidate(x, nullptr, distance_, [&](const Pair& p) {
    with_arity(p.kind, [&](auto k) {
      constexpr int K = decltype(k)::value;
      const std::array<Vec3, K> at = m.positions<K>(p, x);
      if (!(m.gap<K>(p, at, nullptr, nullptr) < distance_)) return;
      VecN<3 * K> g;
      const double d = m.gap<K>(p, at, &g, nullptr);
      const std::array<int, K> nodes = m.nodes<K>(p);
      // The gradient is NaN where the energy is +inf.
      const double scale = d > 0 ? stiffness_ * barrier(d, distance_).first : kNaN;
      for (int a = 0; a < K; ++a)
        gradient.segment<3>(3 * nodes[a]) += scale * g.template segment<3>(3 * a);
    });
  });
}

void ObstacleContact::hessian_elements(ElementNodes& elements) const {
  const Impl& m = *impl_;
  for (int v : m.vertices) elements.add({v});
  for (const auto& e : m.edges) elements.add({e[0], e[1]});
  for (const auto& t : m.triangles) elements.add({t[0], t[1], t[2]});
}

void ObstacleContact::add_hessian(const Positions& x, ElementHessianSink& sink,
                                  bool project_psd) const {
  const Impl& m = *impl_;
  // The pairs within d̂, element by element (a counting sort).
  std::vector<Pair> active;
  m.for_each_candidate(x, nullptr, distance_, [&](const Pair& p) {
    const double d = with_arity(p.kind, [&](auto k) {
      constexpr int K = decltype(k)::value;
      return m.gap<K>(p, m.positions<K>(p, x), nullptr, nullptr);
    });
    if (d < distance_) active.push_back(p);
  });
  const std::size_t element_count = m.vertices.size() + m.edges.size() + m.triangles.size();
  std::vector<int> offsets(element_count + 1, 0);
  for (const Pair& p : active) ++offsets[m.element(p) + 1];
  for (std::size_t e = 0; e < element_count; ++e) offsets[e + 1] += offsets[e];
  std::vector<Pair> by_element(active.size());
  {
    std::vector<int> next(offsets.begin(), offsets.end() - 1);
    for (const Pair& p : active) by_element[next[m.element(p)]++] = p;
  }
  sink.add_blocks([&](std::size_t e, double* block) {
    const int count = e < m.vertices.size() ? 1 : e < m.vertices.size() + m.edges.size() ? 2 : 3;
    const int dofs = 3 * count;
    std::fill(block, block + dofs * dofs, 0.0);
    for (int i = offsets[e]; i < offsets[e + 1]; ++i) {
      const Pair& p = by_element[i];
      with_arity(p.kind, [&](auto k) {
        constexpr int K = decltype(k)::value;
        constexpr int N = 3 * K;
        VecN<N> g;
        MatN<N> h;
        const double d = m.gap<K>(p, m.positions<K>(p, x), &g, &h);
        if (!(d > 0)) {  // intersecting: a NaN block, so the factorization fails
          std::fill(block, block + N * N, kNaN);
          return;
        }
        const BarrierValue b = barrier(d, distance_);
        MatN<N> H = stiffness_ * (b.second * g * g.transpose() + b.first * h);
        if (project_psd) clamp_negative_eigenvalues<N>(H);
        Eigen::Map<MatN<N>>{block} += H;
      });
    }
  });
}

double ObstacleContact::max_step(const Positions& x, const Eigen::VectorXd& dx) const {
  const Impl& m = *impl_;
  double alpha = 1;
  m.for_each_candidate(x, &dx, distance_, [&](const Pair& p) {
    with_arity(p.kind, [&](auto k) {
      constexpr int K = decltype(k)::value;
      const std::array<int, K> nodes = m.nodes<K>(p);
      std::array<Vec3, K> at = m.positions<K>(p, x);
      const double d0 = m.gap<K>(p, at, nullptr, nullptr);
      if (!(d0 > 0)) return;  // already intersecting: no step keeps it out
      const double target = 0.1 * d0;
      if (p.kind == PairKind::VertexHalfSpace) {  // the gap is linear in α: exact
        const double rate = dx.segment<3>(3 * nodes[0]).dot(m.planes[p.other].h.normal);
        if (rate < 0) alpha = std::min(alpha, (d0 - target) / -rate);
        return;
      }
      // Additive CCD (Li et al. 2021): the gap changes no faster than the largest node
      // displacement l, so from t with gap d it stays ≥ target up to t + (d − target)/l.
      double l = 0;
      for (int a = 0; a < K; ++a) l = std::max(l, dx.segment<3>(3 * nodes[a]).norm());
      if (!(l > 0)) return;
      double t = 0, d = d0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        t += (d - target) / l;
        if (t >= alpha) return;
        for (int a = 0; a < K; ++a) at[a] = node(x, nodes[a]) + t * dx.segment<3>(3 * nodes[a]);
        d = m.gap<K>(p, at, nullptr, nullptr);
        // Close enough to the target: further steps would shrink geometrically.
        if (d - target <= 0.1 * (d0 - target)) break;
      }
      alpha = std::min(alpha, t);
    });
  });
  return alpha;
}

ContactSummary ObstacleContact::summary(const Positions& x) const {
  const Impl& m = *impl_;
  ContactSummary s;
  s.min_distance = kInf;
  s.by_obstacle.resize(obstacles_.size());
  m.for_each_candidate(x, nullptr, distance_, [&](const Pair& p) {
    with_arity(p.kind, [&](auto k) {
      constexpr int K = decltype(k)::value;
      const std::array<Vec3, K> at = m.positions<K>(p, x);
      if (!(m.gap<K>(p, at, nullptr, nullptr) < distance_)) return;
      VecN<3 * K> g;
      ContactPoint c;
      c.obstacle = m.obstacle(p);
      c.distance = m.gap<K>(p, at, &g, nullptr);
      // −∂E/∂x summed over the pair's nodes; an intersecting pair (d ≤ 0) is listed with none.
      if (c.distance > 0) {
        const double scale = -stiffness_ * barrier(c.distance, distance_).first;
        for (int a = 0; a < K; ++a) c.force += scale * g.template segment<3>(3 * a);
      }
      if constexpr (K == 1) {
        c.point = at[0];
      } else if constexpr (K == 2) {
        const Segment& seg = m.segments[p.other];
        c.point = at[0] + segment_segment_closest(at[0], at[1], seg.a, seg.b).s * (at[1] - at[0]);
      } else {
        point_triangle_region(m.points[p.other].p, at[0], at[1], at[2], &c.point);
      }
      ++s.count;
      s.min_distance = std::min(s.min_distance, c.distance);
      s.force_total += c.force;
      ++s.by_obstacle[c.obstacle].count;
      s.by_obstacle[c.obstacle].force += c.force;
      s.points.push_back(c);
    });
  });
  return s;
}

std::array<int, 2> ObstacleContact::first_intersection(const Positions& x) const {
  const Impl& m = *impl_;
  for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t) {
    const auto& tri = m.triangles[t];
    const Vec3 a = node(x, tri[0]), b = node(x, tri[1]), c = node(x, tri[2]);
    for (const Plane& plane : m.planes)
      for (const Vec3& p : {a, b, c})
        if (!((p - plane.h.point).dot(plane.h.normal) > 0)) return {plane.obstacle, t};
    const Aabb box = box_of({a, b, c}, 0);
    int found = -1;
    m.triangle_bvh.query(box, [&](int i) {
      if (found >= 0) return;
      const Triangle& o = m.obstacle_triangles[i];
      // Two triangles meet where an edge of one meets the other.
      const std::array<Vec3, 3> A{a, b, c}, B{o.a, o.b, o.c};
      for (int k = 0; k < 3 && found < 0; ++k)
        if (segment_triangle_distance(A[k], A[(k + 1) % 3], o.a, o.b, o.c) <= o.radius ||
            segment_triangle_distance(B[k], B[(k + 1) % 3], a, b, c) <= o.radius)
          found = o.obstacle;
    });
    m.segment_bvh.query(box, [&](int i) {
      const Segment& s = m.segments[i];
      if (found < 0 && segment_triangle_distance(s.a, s.b, a, b, c) <= s.radius) found = s.obstacle;
    });
    m.point_bvh.query(box, [&](int i) {
      const Point& q = m.points[i];
      if (found < 0 &&
          point_triangle_distance<0>(q.p, a, b, c, {false, false, false, false}) <= q.radius)
        found = q.obstacle;
    });
    if (found >= 0) return {found, t};
  }
  return {-1, -1};
}

double default_contact_stiffness(double weight, int node_count, double distance) {
  if (!(weight >= 0) || !std::isfinite(weight) || node_count <= 0 || !(distance > 0) ||
      !std::isfinite(distance))
    throw std::invalid_argument(
        "default_contact_stiffness: expected weight >= 0, node_count > 0, distance > 0");
  // |b′(d̂/2)| = d̂ (ln 2 + 1/2).
  return weight / node_count / std::abs(barrier(0.5 * distance, distance).first);
}

}  // namespace shapectl
