#include <shapectl/contact/obstacle_contact.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>

#include <shapectl/contact/barrier.hpp>
#include <shapectl/contact/bvh.hpp>
#include <shapectl/contact/distance_piece.hpp>
#include <shapectl/contact/point_segment_distance.hpp>
#include <shapectl/contact/point_triangle_distance.hpp>
#include <shapectl/contact/segment_segment_distance.hpp>
#include <shapectl/contact/segment_triangle_distance.hpp>
#include <shapectl/contact/triangle_edges.hpp>

// How the terms are found: the broad phase lists candidates, pairs of primitives (Pair) whose
// boxes overlap; IPC's classification of where their closest points lie turns each into a
// Contact, a pair of features, and a contact found by several candidates counts once. The CCD
// bound works on the candidates themselves.
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
  Vec3 normal;                 // unit (zero if degenerate)
  std::array<int, 3> corners;  // into Impl::points
  std::array<int, 3> sides;    // into Impl::segments: side k joins corners k and k + 1
};
struct Segment {
  int obstacle;
  Vec3 a, b;
  double radius;
  std::array<int, 2> ends;  // into Impl::points
};

// What is in contact: a feature of the object's surface (a vertex, the inside of an edge or
// of a triangle: its Hessian element) and one of an obstacle's (a point, the inside of a
// segment or of a triangle, a half-space), each pair counted once however many primitive pairs
// find it. Packed in 64 bits, element first, so sorting groups contacts by element.
enum class Feature : std::uint64_t { Point = 0, Segment = 1, Triangle = 2, HalfSpace = 3 };
struct Contact {
  int element;
  Feature feature;
  int index;  // into Impl's points, segments, obstacle_triangles or planes

  std::uint64_t key() const {
    return (std::uint64_t(element) << 32) | (std::uint64_t(feature) << 30) | std::uint64_t(index);
  }
  static Contact from(std::uint64_t key) {
    return {int(key >> 32), Feature((key >> 30) & 3), int(key & ((1u << 30) - 1))};
  }
};
struct Point {
  int obstacle;
  Vec3 p;
  double radius;
};

Vec3 node(const Positions& x, int i) { return x.segment<3>(3 * i); }

// f(std::integral_constant<int, K>()) for an element of K nodes.
template <class F>
decltype(auto) with_element_size(int K, F&& f) {
  switch (K) {
    case 1: return f(std::integral_constant<int, 1>());
    case 2: return f(std::integral_constant<int, 2>());
    default: return f(std::integral_constant<int, 3>());
  }
}

}  // namespace

struct ObstacleContact::Impl {
  // The object's surface.
  std::vector<int> vertices;
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::array<int, 2>> edge_vertices;      // into vertices
  std::vector<std::array<int, 3>> triangle_vertices;  // into vertices
  std::vector<std::array<int, 3>> triangle_edges;     // edge k joins corners k and k + 1
  // The obstacles' primitives, and the hierarchies each kind of object primitive searches.
  std::vector<Plane> planes;
  std::vector<Triangle> obstacle_triangles;
  std::vector<Segment> segments;                    // every segment: against object edges
  std::vector<Point> points;                        // every point: against object triangles
  std::vector<int> vertex_segments, vertex_points;  // those an object vertex meets directly
  Bvh triangle_bvh, segment_bvh, point_bvh, vertex_segment_bvh, vertex_point_bvh;
  int node_count = 0;
  // Per obstacle: ignores[o][node] if o never touches that node (empty: it touches every node).
  std::vector<std::vector<char>> ignores;

  // The obstacles' primitives in the world: those on links placed by T_world_link (per link).
  void set_obstacles(const std::vector<Obstacle>& obstacles,
                     const std::vector<Eigen::Isometry3d>& T_world_link);

  // Whether the obstacle ignores one of the nodes.
  template <std::size_t K>
  bool ignores_any(int obstacle, const std::array<int, K>& nodes) const {
    const std::vector<char>& ignore = ignores[static_cast<std::size_t>(obstacle)];
    if (ignore.empty()) return false;
    for (int n : nodes)
      if (ignore[static_cast<std::size_t>(n)]) return true;
    return false;
  }
  // Whether the pair's obstacle ignores one of its object nodes (they are then no pair at all).
  template <int K>
  bool ignored(const Pair& p) const {
    return ignores_any(obstacle(p), nodes<K>(p));
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

  // The gap of candidate p with its object nodes at `at`: the distance between its two
  // primitives less the obstacle's radius (for CCD; the energy uses contact_gap). With
  // `moved`, the obstacle's primitive moved rigidly by it first (not a half-space's).
  template <int K>
  double candidate_gap(const Pair& p, const std::array<Vec3, K>& at,
                       const Eigen::Isometry3d* moved = nullptr) const {
    constexpr std::array<bool, 4> fixed{false, false, false, false};
    const auto place = [moved](const Vec3& v) -> Vec3 { return moved ? Vec3(*moved * v) : v; };
    if constexpr (K == 1) {
      switch (p.kind) {
        case PairKind::VertexHalfSpace:
          return (at[0] - planes[p.other].h.point).dot(planes[p.other].h.normal);
        case PairKind::VertexTriangle: {
          const Triangle& t = obstacle_triangles[p.other];
          return point_triangle_distance<0>(at[0], place(t.a), place(t.b), place(t.c), fixed) -
                 t.radius;
        }
        case PairKind::VertexSegment: {
          const Segment& s = segments[p.other];
          return point_segment_distance<0>(at[0], place(s.a), place(s.b), {false, false, false}) -
                 s.radius;
        }
        default: return (at[0] - place(points[p.other].p)).norm() - points[p.other].radius;
      }
    } else if constexpr (K == 2) {
      const Segment& s = segments[p.other];
      return segment_segment_distance<0>(at[0], at[1], place(s.a), place(s.b), fixed) - s.radius;
    } else {
      const Point& q = points[p.other];
      return point_triangle_distance<0>(place(q.p), at[0], at[1], at[2], fixed) - q.radius;
    }
  }

  // The points spanning candidate p's obstacle primitive (world): a triangle's corners, a
  // segment's ends, a point; none for a half-space. Returns how many.
  int obstacle_points(const Pair& p, std::array<Vec3, 3>& out) const {
    switch (p.kind) {
      case PairKind::VertexHalfSpace: return 0;
      case PairKind::VertexTriangle: {
        const Triangle& t = obstacle_triangles[p.other];
        out = {t.a, t.b, t.c};
        return 3;
      }
      case PairKind::VertexSegment:
      case PairKind::SegmentEdge:
        out[0] = segments[p.other].a;
        out[1] = segments[p.other].b;
        return 2;
      default: out[0] = points[p.other].p; return 1;
    }
  }

  template <int K>
  std::array<Vec3, K> positions(const Pair& p, const Positions& x) const {
    const std::array<int, K> n = nodes<K>(p);
    std::array<Vec3, K> at;
    for (int k = 0; k < K; ++k) at[k] = node(x, n[k]);
    return at;
  }

  // Elements: the surface's vertices, then its edges, then its triangles; K nodes each.
  int element_size(int element) const {
    const int v = static_cast<int>(vertices.size()), e = static_cast<int>(edges.size());
    return element < v ? 1 : element < v + e ? 2 : 3;
  }
  int element_size(const Contact& c) const { return element_size(c.element); }
  int edge_element(int edge) const { return static_cast<int>(vertices.size()) + edge; }
  int triangle_element(int triangle) const {
    return static_cast<int>(vertices.size() + edges.size()) + triangle;
  }

  template <int K>
  std::array<int, K> element_nodes(int element) const {
    if constexpr (K == 1) return {vertices[element]};
    if constexpr (K == 2) return edges[element - vertices.size()];
    if constexpr (K == 3) return triangles[element - vertices.size() - edges.size()];
  }

  template <int K>
  std::array<Vec3, K> element_positions(int element, const Positions& x) const {
    const std::array<int, K> n = element_nodes<K>(element);
    std::array<Vec3, K> at;
    for (int k = 0; k < K; ++k) at[k] = node(x, n[k]);
    return at;
  }

  int obstacle(const Contact& c) const {
    switch (c.feature) {
      case Feature::Point: return points[c.index].obstacle;
      case Feature::Segment: return segments[c.index].obstacle;
      case Feature::Triangle: return obstacle_triangles[c.index].obstacle;
      default: return planes[c.index].obstacle;
    }
  }

  // The gap of contact c with its element's nodes at `at`: the one smooth piece its features
  // give (point–point, point–line, point–plane, line–line) less the obstacle's radius; its
  // gradient and Hessian with respect to the nodes' coordinates if asked (may be null).
  template <int K>
  double contact_gap(const Contact& c, const std::array<Vec3, K>& at, VecN<3 * K>* g,
                     MatN<3 * K>* h) const {
    using namespace contact;
    constexpr int N = 3 * K;
    if constexpr (K == 1) {
      switch (c.feature) {
        case Feature::HalfSpace: {
          const HalfSpace& s = planes[c.index].h;
          if (g) *g = s.normal;
          if (h) h->setZero();
          return (at[0] - s.point).dot(s.normal);
        }
        case Feature::Point: {
          const Point& q = points[c.index];
          return evaluate_piece<N>([](const auto& P) { return point_point_piece(P[0], P[1]); },
                                   std::array<Vec3, 2>{at[0], q.p}, {true, false}, g, h) -
                 q.radius;
        }
        case Feature::Segment: {
          const Segment& s = segments[c.index];
          return evaluate_piece<N>([](const auto& P) { return point_line_piece(P[0], P[1], P[2]); },
                                   std::array<Vec3, 3>{at[0], s.a, s.b}, {true, false, false}, g,
                                   h) -
                 s.radius;
        }
        case Feature::Triangle: {
          const Triangle& t = obstacle_triangles[c.index];
          return evaluate_piece<N>(
                     [](const auto& P) { return point_plane_piece(P[0], P[1], P[2], P[3]); },
                     std::array<Vec3, 4>{at[0], t.a, t.b, t.c}, {true, false, false, false}, g, h) -
                 t.radius;
        }
      }
    } else if constexpr (K == 2) {
      if (c.feature == Feature::Point) {
        const Point& q = points[c.index];
        return evaluate_piece<N>([](const auto& P) { return point_line_piece(P[2], P[0], P[1]); },
                                 std::array<Vec3, 3>{at[0], at[1], q.p}, {true, true, false}, g,
                                 h) -
               q.radius;
      }
      if (c.feature == Feature::Segment) {
        const Segment& s = segments[c.index];
        return evaluate_piece<N>(
                   [](const auto& P) { return line_line_piece(P[0], P[1], P[2], P[3]); },
                   std::array<Vec3, 4>{at[0], at[1], s.a, s.b}, {true, true, false, false}, g, h) -
               s.radius;
      }
    } else if (c.feature == Feature::Point) {
      const Point& q = points[c.index];
      return evaluate_piece<N>(
                 [](const auto& P) { return point_plane_piece(P[3], P[0], P[1], P[2]); },
                 std::array<Vec3, 4>{at[0], at[1], at[2], q.p}, {true, true, true, false}, g, h) -
             q.radius;
    }
    return kNaN;  // no such pair of features
  }

  // The obstacle feature's points, world: a point, a segment's ends or a triangle's corners.
  static int feature_point_count(Feature f) {
    return f == Feature::Point ? 1 : f == Feature::Segment ? 2 : f == Feature::Triangle ? 3 : 0;
  }
  template <int P>
  std::array<Vec3, P> feature_points(const Contact& c) const {
    if constexpr (P == 1) return {points[c.index].p};
    if constexpr (P == 2) return {segments[c.index].a, segments[c.index].b};
    if constexpr (P == 3)
      return {obstacle_triangles[c.index].a, obstacle_triangles[c.index].b,
              obstacle_triangles[c.index].c};
  }
  double feature_radius(const Contact& c) const {
    switch (c.feature) {
      case Feature::Point: return points[c.index].radius;
      case Feature::Segment: return segments[c.index].radius;
      case Feature::Triangle: return obstacle_triangles[c.index].radius;
      default: return 0;
    }
  }

  // The pairs of features a contact can be: K element nodes against P obstacle points.
  template <int K, int P>
  static constexpr bool coupled = K == 1 || P == 1 || (K == 2 && P == 2);

  // contact_gap with the obstacle's P points `q` as variables too: its gradient and Hessian
  // with respect to the element's node coordinates, then the points'.
  template <int K, int P>
  double coupled_gap(const Contact& c, const std::array<Vec3, K>& at, const std::array<Vec3, P>& q,
                     VecN<3 * (K + P)>& g, MatN<3 * (K + P)>& h) const {
    using namespace contact;
    std::array<Vec3, K + P> all;
    std::array<bool, K + P> varies;
    for (int k = 0; k < K; ++k) all[k] = at[k];
    for (int j = 0; j < P; ++j) all[K + j] = q[j];
    varies.fill(true);
    const auto piece = [](const auto& X) {
      if constexpr (K == 1 && P == 1) return point_point_piece(X[0], X[1]);
      else if constexpr (K == 1 && P == 2) return point_line_piece(X[0], X[1], X[2]);
      else if constexpr (K == 1 && P == 3) return point_plane_piece(X[0], X[1], X[2], X[3]);
      else if constexpr (K == 2 && P == 1) return point_line_piece(X[2], X[0], X[1]);
      else if constexpr (K == 2 && P == 2) return line_line_piece(X[0], X[1], X[2], X[3]);
      else return point_plane_piece(X[3], X[0], X[1], X[2]);  // K == 3, P == 1
    };
    return evaluate_piece<3 * (K + P)>(piece, all, varies, &g, &h) - feature_radius(c);
  }

  // Where on the object contact c's closest point lies.
  template <int K>
  Vec3 closest_on_object(const Contact& c, const std::array<Vec3, K>& at) const {
    if constexpr (K == 1) {
      return at[0];
    } else if constexpr (K == 2) {
      const Vec3 e = at[1] - at[0];
      if (c.feature == Feature::Point)
        return at[0] + (points[c.index].p - at[0]).dot(e) / e.squaredNorm() * e;
      const Segment& s = segments[c.index];
      return at[0] + segment_segment_closest(at[0], at[1], s.a, s.b).s * e;
    } else {
      const Vec3 n = (at[1] - at[0]).cross(at[2] - at[0]);
      const Vec3& q = points[c.index].p;
      return q - (q - at[0]).dot(n) / n.squaredNorm() * n;
    }
  }

  // The contact candidate p finds at x: the features its closest points lie on.
  Contact classify(const Pair& p, const Positions& x) const {
    switch (p.kind) {
      case PairKind::VertexHalfSpace: return {p.object, Feature::HalfSpace, p.other};
      case PairKind::VertexPoint: return {p.object, Feature::Point, p.other};
      case PairKind::VertexTriangle: {
        const Triangle& t = obstacle_triangles[p.other];
        switch (point_triangle_region(node(x, vertices[p.object]), t.a, t.b, t.c)) {
          case PointTriangleRegion::A: return {p.object, Feature::Point, t.corners[0]};
          case PointTriangleRegion::B: return {p.object, Feature::Point, t.corners[1]};
          case PointTriangleRegion::C: return {p.object, Feature::Point, t.corners[2]};
          case PointTriangleRegion::AB: return {p.object, Feature::Segment, t.sides[0]};
          case PointTriangleRegion::BC: return {p.object, Feature::Segment, t.sides[1]};
          case PointTriangleRegion::CA: return {p.object, Feature::Segment, t.sides[2]};
          case PointTriangleRegion::Face: break;
        }
        return {p.object, Feature::Triangle, p.other};
      }
      case PairKind::VertexSegment: {
        const Segment& s = segments[p.other];
        switch (point_segment_region(node(x, vertices[p.object]), s.a, s.b)) {
          case PointSegmentRegion::A: return {p.object, Feature::Point, s.ends[0]};
          case PointSegmentRegion::B: return {p.object, Feature::Point, s.ends[1]};
          case PointSegmentRegion::Interior: break;
        }
        return {p.object, Feature::Segment, p.other};
      }
      case PairKind::SegmentEdge: {
        const Segment& s = segments[p.other];
        const auto& e = edges[p.object];
        const SegmentSegmentClosest c =
            segment_segment_closest(node(x, e[0]), node(x, e[1]), s.a, s.b);
        const int element =
            c.s_inside ? edge_element(p.object) : edge_vertices[p.object][c.s < 0.5 ? 0 : 1];
        if (c.t_inside) return {element, Feature::Segment, p.other};
        return {element, Feature::Point, s.ends[c.t < 0.5 ? 0 : 1]};
      }
      case PairKind::PointTriangle: break;
    }
    const auto& t = triangles[p.object];
    const auto& tv = triangle_vertices[p.object];
    const auto& te = triangle_edges[p.object];
    switch (point_triangle_region(points[p.other].p, node(x, t[0]), node(x, t[1]), node(x, t[2]))) {
      case PointTriangleRegion::A: return {tv[0], Feature::Point, p.other};
      case PointTriangleRegion::B: return {tv[1], Feature::Point, p.other};
      case PointTriangleRegion::C: return {tv[2], Feature::Point, p.other};
      case PointTriangleRegion::AB: return {edge_element(te[0]), Feature::Point, p.other};
      case PointTriangleRegion::BC: return {edge_element(te[1]), Feature::Point, p.other};
      case PointTriangleRegion::CA: return {edge_element(te[2]), Feature::Point, p.other};
      case PointTriangleRegion::Face: break;
    }
    return {triangle_element(p.object), Feature::Point, p.other};
  }

  // Calls visit(contact) once for every contact closer than d̂ at x. Half-spaces directly (one
  // contact per vertex, no allocation); the rest through their candidates, sorted and merged.
  template <class Visit>
  void for_each_contact(const Positions& x, double dhat, Visit&& visit) const {
    std::vector<std::uint64_t> keys;
    for_each_candidate(x, nullptr, dhat, [&](const Pair& p) {
      const Contact c = classify(p, x);
      if (p.kind == PairKind::VertexHalfSpace) {
        visit(c);
        return;
      }
      const double d = with_element_size(element_size(c), [&](auto k) {
        constexpr int K = decltype(k)::value;
        return contact_gap<K>(c, element_positions<K>(c.element, x), nullptr, nullptr);
      });
      if (d < dhat) keys.push_back(c.key());
    });
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    for (std::uint64_t key : keys) visit(Contact::from(key));
  }

  // Calls visit(pair) for every pair whose boxes overlap: the object primitive's box at x
  // (swept to x + dx if dx is not null) inflated by `inflate`, the obstacle primitive's by its
  // radius. Half-spaces: every vertex whose gap is below `inflate` at x or x + dx.
  template <class Visit>
  void for_each_candidate(const Positions& x, const Eigen::VectorXd* dx, double inflate,
                          Visit&& visit_any) const {
    const auto visit = [&](const Pair& p) {
      const bool skip =
          with_element_size(arity(p.kind), [&](auto k) { return ignored<decltype(k)::value>(p); });
      if (!skip) visit_any(p);
    };
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
      const Vec3 q = dx ? Vec3(p + dx->segment<3>(3 * vertices[v])) : p;
      triangle_bvh.query(box, [&](int i) {
        // Far from the triangle's plane all the way (its distance is at least that): no pair.
        const Triangle& t = obstacle_triangles[i];
        const double far = t.radius + inflate, dp = (p - t.a).dot(t.normal),
                     dq = (q - t.a).dot(t.normal);
        if ((dp >= far && dq >= far) || (dp <= -far && dq <= -far)) return;
        visit(Pair{PairKind::VertexTriangle, v, i});
      });
      vertex_segment_bvh.query(box, [&](int i) {
        visit(Pair{PairKind::VertexSegment, v, vertex_segments[i]});
      });
      vertex_point_bvh.query(box, [&](int i) {
        visit(Pair{PairKind::VertexPoint, v, vertex_points[i]});
      });
    }
    if (!segment_bvh.empty())
      for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
        const Aabb box = box_of({edges[e][0], edges[e][1]});
        segment_bvh.query(box, [&](int i) {
          // A long segment (a box's diagonal) has a big box: test the segment itself.
          const Segment& s = segments[i];
          if (segment_overlaps(s.a, s.b, box.inflated(s.radius)))
            visit(Pair{PairKind::SegmentEdge, e, i});
        });
      }
    if (!point_bvh.empty())
      for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
        const auto& tri = triangles[t];
        const Vec3 a = node(x, tri[0]);
        Vec3 n = (node(x, tri[1]) - a).cross(node(x, tri[2]) - a);
        n /= n.norm();
        point_bvh.query(box_of({tri[0], tri[1], tri[2]}), [&](int i) {
          // At x only (the plane turns along a step): far from the triangle's plane.
          const Point& q = points[i];
          if (!dx && std::abs((q.p - a).dot(n)) >= q.radius + inflate) return;
          visit(Pair{PairKind::PointTriangle, t, i});
        });
      }
  }
};

namespace {

// f(std::integral_constant<int, K>()) with K the pair's object node count.
template <class F>
decltype(auto) with_arity(PairKind kind, F&& f) {
  return with_element_size(arity(kind), std::forward<F>(f));
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

void ObstacleContact::Impl::set_obstacles(const std::vector<Obstacle>& given,
                                          const std::vector<Eigen::Isometry3d>& T_world_link) {
  planes.clear();
  obstacle_triangles.clear();
  segments.clear();
  points.clear();
  vertex_segments.clear();
  vertex_points.clear();
  ignores.assign(given.size(), {});
  std::vector<Aabb> triangle_boxes, segment_boxes, point_boxes, vertex_segment_boxes,
      vertex_point_boxes;
  for (int o = 0; o < static_cast<int>(given.size()); ++o) {
    if (given[o].link >= 0 && given[o].link >= static_cast<int>(T_world_link.size()))
      throw std::invalid_argument("obstacle '" + given[o].name +
                                  "' is on a robot link: its pose is needed");
    const Obstacle ob =
        given[o].link >= 0 ? moved(given[o], T_world_link[given[o].link]) : given[o];
    if (!ob.ignored_nodes.empty()) {
      ignores[o].assign(static_cast<std::size_t>(node_count), 0);
      for (int n : ob.ignored_nodes) ignores[o][static_cast<std::size_t>(n)] = 1;
    }
    const double r = ob.radius;
    if (ob.plane) planes.push_back({o, *ob.plane});
    const int first_point = static_cast<int>(points.size());
    for (const Vec3& p : ob.points) {
      if (ob.triangles.empty() && ob.edges.empty()) {
        vertex_points.push_back(static_cast<int>(points.size()));
        vertex_point_boxes.push_back(box_of({p}, r));
      }
      points.push_back({o, p, r});
      point_boxes.push_back(box_of({p}, r));
    }
    // An object vertex meets a triangle's edges and corners through the point–triangle
    // distance, a segment's ends through the point–segment distance.
    std::map<std::array<int, 2>, int> segment_index;
    for (const auto& e : ob.edges) {
      if (ob.triangles.empty()) {
        vertex_segments.push_back(static_cast<int>(segments.size()));
        vertex_segment_boxes.push_back(box_of({ob.points[e[0]], ob.points[e[1]]}, r));
      }
      segment_index[{std::min(e[0], e[1]), std::max(e[0], e[1])}] =
          static_cast<int>(segments.size());
      segments.push_back(
          {o, ob.points[e[0]], ob.points[e[1]], r, {first_point + e[0], first_point + e[1]}});
      segment_boxes.push_back(box_of({ob.points[e[0]], ob.points[e[1]]}, r));
    }
    for (const auto& t : ob.triangles) {
      std::array<int, 3> corners, sides;
      for (int k = 0; k < 3; ++k) {
        const int i = t[k], j = t[(k + 1) % 3];
        const auto side = segment_index.find({std::min(i, j), std::max(i, j)});
        if (side == segment_index.end())
          throw std::invalid_argument("obstacle '" + ob.name + "': the edge " + std::to_string(i) +
                                      "-" + std::to_string(j) +
                                      " of a triangle is not among its edges");
        corners[k] = first_point + i;
        sides[k] = side->second;
      }
      const Vec3 n = (ob.points[t[1]] - ob.points[t[0]]).cross(ob.points[t[2]] - ob.points[t[0]]);
      obstacle_triangles.push_back({o, ob.points[t[0]], ob.points[t[1]], ob.points[t[2]], r,
                                    n.norm() > 0 ? Vec3(n.normalized()) : Vec3::Zero(), corners,
                                    sides});
      triangle_boxes.push_back(box_of({ob.points[t[0]], ob.points[t[1]], ob.points[t[2]]}, r));
    }
  }
  triangle_bvh = Bvh(triangle_boxes);
  segment_bvh = Bvh(segment_boxes);
  point_bvh = Bvh(point_boxes);
  vertex_segment_bvh = Bvh(vertex_segment_boxes);
  vertex_point_bvh = Bvh(vertex_point_boxes);
}

ObstacleContact::ObstacleContact(const TetMesh& mesh, std::vector<Obstacle> obstacles,
                                 double distance, double stiffness,
                                 const std::vector<Eigen::Isometry3d>& T_world_link)
    : obstacles_(std::make_shared<const std::vector<Obstacle>>(std::move(obstacles))),
      distance_(distance),
      stiffness_(stiffness) {
  check_barrier_parameters("ObstacleContact", distance, stiffness);
  auto m = std::make_shared<Impl>();
  m->triangles = mesh.surface_triangles();
  m->edges = triangle_edges(m->triangles);
  m->vertices = triangle_corners(m->triangles);
  // The surface's features by index: which vertices an edge joins, which a triangle's.
  std::vector<int> vertex_of_node(mesh.node_count(), -1);
  for (int v = 0; v < static_cast<int>(m->vertices.size()); ++v) vertex_of_node[m->vertices[v]] = v;
  std::map<std::array<int, 2>, int> edge_index;
  for (const auto& e : m->edges) {
    edge_index[e] = static_cast<int>(m->edge_vertices.size());
    m->edge_vertices.push_back({vertex_of_node[e[0]], vertex_of_node[e[1]]});
  }
  for (const auto& t : m->triangles) {
    std::array<int, 3> vs, es;
    for (int k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3];
      vs[k] = vertex_of_node[i];
      es[k] = edge_index.at({std::min(i, j), std::max(i, j)});
    }
    m->triangle_vertices.push_back(vs);
    m->triangle_edges.push_back(es);
  }
  m->node_count = mesh.node_count();
  m->set_obstacles(*obstacles_, T_world_link);
  impl_ = std::move(m);
}

bool ObstacleContact::moves() const {
  return std::any_of(obstacles_->begin(), obstacles_->end(),
                     [](const Obstacle& o) { return o.link >= 0; });
}

ObstacleContact ObstacleContact::posed(const std::vector<Eigen::Isometry3d>& T_world_link) const {
  ObstacleContact out = *this;
  if (!moves()) return out;
  auto m = std::make_shared<Impl>(*impl_);  // the surface kept, the obstacles placed anew
  m->set_obstacles(*obstacles_, T_world_link);
  out.impl_ = std::move(m);
  return out;
}

ObstacleContact ObstacleContact::scaled(double factor) const {
  ObstacleContact out = *this;
  out.stiffness_ *= factor;
  check_barrier_parameters("ObstacleContact", distance_, out.stiffness_);
  return out;
}

double ObstacleContact::value(const Positions& x) const {
  const Impl& m = *impl_;
  double sum = 0;
  bool intersecting = false;
  m.for_each_contact(x, distance_, [&](const Contact& c) {
    const double d = with_element_size(m.element_size(c), [&](auto k) {
      constexpr int K = decltype(k)::value;
      return m.contact_gap<K>(c, m.element_positions<K>(c.element, x), nullptr, nullptr);
    });
    if (!(d > 0)) intersecting = true;
    else if (d < distance_) sum += barrier(d, distance_).value;
  });
  return intersecting ? kInf : stiffness_ * sum;
}

void ObstacleContact::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const Impl& m = *impl_;
  m.for_each_contact(x, distance_, [&](const Contact& c) {
    with_element_size(m.element_size(c), [&](auto k) {
      constexpr int K = decltype(k)::value;
      VecN<3 * K> g;
      const double d = m.contact_gap<K>(c, m.element_positions<K>(c.element, x), &g, nullptr);
      if (!(d < distance_)) return;
      const std::array<int, K> nodes = m.element_nodes<K>(c.element);
      // The gradient is NaN where the energy is +inf.
      const double scale = d > 0 ? stiffness_ * barrier(d, distance_).first : kNaN;
      for (int a = 0; a < K; ++a)
        gradient.segment<3>(3 * nodes[a]) += scale * g.template segment<3>(3 * a);
    });
  });
}

void ObstacleContact::hessian_elements(const Positions&, ElementNodes& elements) const {
  const Impl& m = *impl_;
  for (int v : m.vertices) elements.add({v});
  for (const auto& e : m.edges) elements.add({e[0], e[1]});
  for (const auto& t : m.triangles) elements.add({t[0], t[1], t[2]});
}

void ObstacleContact::add_hessian(const Positions& x, ElementHessianSink& sink,
                                  bool project_psd) const {
  const Impl& m = *impl_;
  // The contacts sorted by element, so each element finds its own as one run.
  std::vector<std::uint64_t> keys;
  m.for_each_contact(x, distance_, [&](const Contact& c) { keys.push_back(c.key()); });
  std::sort(keys.begin(), keys.end());
  const std::size_t element_count = m.vertices.size() + m.edges.size() + m.triangles.size();
  std::vector<int> offsets(element_count + 1, 0);
  for (std::uint64_t key : keys) ++offsets[Contact::from(key).element + 1];
  for (std::size_t e = 0; e < element_count; ++e) offsets[e + 1] += offsets[e];
  sink.add_blocks([&](std::size_t e, double* block) {
    const int K = m.element_size(static_cast<int>(e));
    std::fill(block, block + 9 * K * K, 0.0);
    for (int i = offsets[e]; i < offsets[e + 1]; ++i) {
      const Contact c = Contact::from(keys[i]);
      with_element_size(K, [&](auto k) {
        constexpr int N = 3 * decltype(k)::value;
        VecN<N> g;
        MatN<N> h;
        const double d = m.contact_gap<N / 3>(c, m.element_positions<N / 3>(c.element, x), &g, &h);
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
      const double d0 = m.candidate_gap<K>(p, at);
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
        d = m.candidate_gap<K>(p, at);
        // Close enough to the target: further steps would shrink geometrically.
        if (d - target <= 0.1 * (d0 - target)) break;
      }
      alpha = std::min(alpha, t);
    });
  });
  return alpha;
}

double ObstacleContact::max_obstacle_step(const Positions& x, ObstacleMotion& motion,
                                          int* limiting) const {
  if (!moves()) return 1;
  const Impl& m = *impl_;
  const auto link_of = [&](const Pair& p) { return (*obstacles_)[m.obstacle(p)].link; };
  // The farthest any obstacle point travels over the whole path widens the broad phase: a
  // pair missed there stays more than d̂ apart all the way.
  motion.move_to(0);
  double reach = 0;
  for (const Point& q : m.points)
    if (const int link = (*obstacles_)[q.obstacle].link; link >= 0)
      reach = std::max(reach, motion.travel(link, q.p, 1));
  // A candidate whose obstacle moves, with its gap at the start, its target (10 % of it, as
  // max_step's) and its gap now.
  struct Moving {
    Pair pair;
    int link;
    double d0, target, d;
  };
  std::vector<Moving> moving;
  m.for_each_candidate(x, nullptr, distance_ + reach, [&](const Pair& p) {
    const int link = link_of(p);
    if (link < 0) return;  // fixed obstacles: x is clear of them and neither moves
    const double d0 = with_arity(p.kind, [&](auto k) {
      constexpr int K = decltype(k)::value;
      return m.candidate_gap<K>(p, m.positions<K>(p, x));
    });
    if (!(d0 > 0)) return;  // already intersecting: no step keeps it out
    // Pairs whose obstacle cannot travel as far as 90 % of the gap never reach the target.
    std::array<Vec3, 3> q;
    double far = 0;
    for (int i = m.obstacle_points(p, q) - 1; i >= 0; --i)
      far = std::max(far, motion.travel(link, q[i], 1));
    if (far > 0.9 * d0) moving.push_back({p, link, d0, 0.1 * d0, d0});
  });
  // Conservative advancement (Li et al. 2021, additive CCD, with the obstacle moving): from s,
  // no point of a pair's obstacle primitive (a convex combination of its points, moved
  // rigidly) travels farther than its gap less the target before s + h, so every gap stays
  // above its target up to there. Stop where one comes close to its target.
  double s = 0;
  const Moving* slowest = nullptr;  // the pair that bounds the last advance
  for (int iteration = 0; iteration < 1000 && !moving.empty(); ++iteration) {
    double h = kInf;
    for (const Moving& c : moving) {
      std::array<Vec3, 3> q;
      const Eigen::Isometry3d& T = motion.displacement(c.link);
      for (int i = m.obstacle_points(c.pair, q) - 1; i >= 0; --i)
        if (const double t = motion.time_to_travel(c.link, T * q[i], c.d - c.target); t < h) {
          h = t;
          slowest = &c;
        }
    }
    if (!(s + h < 1)) return 1;
    s += h;
    motion.move_to(s);
    for (Moving& c : moving) {
      c.d = with_arity(c.pair.kind, [&](auto k) {
        constexpr int K = decltype(k)::value;
        return m.candidate_gap<K>(c.pair, m.positions<K>(c.pair, x), &motion.displacement(c.link));
      });
      // Close enough to the target: further steps would shrink geometrically.
      if (c.d - c.target <= 0.1 * (c.d0 - c.target)) {
        if (limiting) *limiting = m.obstacle(c.pair);
        return s;
      }
    }
  }
  if (!slowest) return 1;
  if (limiting) *limiting = m.obstacle(slowest->pair);  // 1000 advances: a bound all the same
  return s;
}

void ObstacleContact::for_each_coupling(const Positions& x, const CouplingVisit& visit) const {
  const Impl& m = *impl_;
  m.for_each_contact(x, distance_, [&](const Contact& c) {
    const int o = m.obstacle(c);
    if ((*obstacles_)[static_cast<std::size_t>(o)].link < 0) return;  // fixed: no coupling
    const int P = Impl::feature_point_count(c.feature);
    if (P == 0) return;
    with_element_size(m.element_size(c), [&](auto k) {
      with_element_size(P, [&](auto q) {
        constexpr int K = decltype(k)::value, Q = decltype(q)::value, N = 3 * (K + Q);
        if constexpr (Impl::coupled<K, Q>) {
          const std::array<Vec3, Q> points = m.feature_points<Q>(c);
          VecN<N> g;
          MatN<N> h;
          const double d =
              m.coupled_gap<K, Q>(c, m.element_positions<K>(c.element, x), points, g, h);
          if (!(d > 0 && d < distance_)) return;
          const BarrierValue b = barrier(d, distance_);
          const MatN<N> H = stiffness_ * (b.second * g * g.transpose() + b.first * h);
          const std::array<int, K> nodes = m.element_nodes<K>(c.element);
          for (int a = 0; a < K; ++a)
            for (int j = 0; j < Q; ++j)
              visit(nodes[a], o, points[j], H.template block<3, 3>(3 * a, 3 * (K + j)));
        }
      });
    });
  });
}

ContactSummary ObstacleContact::summary(const Positions& x) const {
  const Impl& m = *impl_;
  ContactSummary s;
  s.min_distance = kInf;
  s.stiffness = stiffness_;
  s.by_obstacle.resize(obstacles_->size());
  m.for_each_contact(x, distance_, [&](const Contact& contact) {
    with_element_size(m.element_size(contact), [&](auto k) {
      constexpr int K = decltype(k)::value;
      const std::array<Vec3, K> at = m.element_positions<K>(contact.element, x);
      VecN<3 * K> g;
      ContactPoint c;
      c.obstacle = m.obstacle(contact);
      c.distance = m.contact_gap<K>(contact, at, &g, nullptr);
      if (!(c.distance < distance_)) return;
      // −∂E/∂x summed over the contact's nodes; an intersecting one (d ≤ 0) is listed with none.
      if (c.distance > 0) {
        const double scale = -stiffness_ * barrier(c.distance, distance_).first;
        for (int a = 0; a < K; ++a) c.force += scale * g.template segment<3>(3 * a);
      }
      c.point = m.closest_on_object<K>(contact, at);
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

std::vector<ContactPair> ObstacleContact::pairs(const Positions& x) const {
  std::vector<ContactPair> out;
  for (const ContactPairDerivatives& p : pair_derivatives(x)) out.push_back(p.pair);
  return out;
}

std::vector<ContactPairDerivatives> ObstacleContact::pair_derivatives(const Positions& x) const {
  const Impl& m = *impl_;
  std::vector<ContactPairDerivatives> out;
  m.for_each_contact(x, distance_, [&](const Contact& contact) {
    with_element_size(m.element_size(contact), [&](auto k) {
      constexpr int K = decltype(k)::value, N = 3 * K;
      VecN<N> g;
      MatN<N> h;
      const double d =
          m.contact_gap<K>(contact, m.element_positions<K>(contact.element, x), &g, &h);
      if (!(d > 0 && d < distance_)) return;
      // ∂d/∂x_a = w_a n (the closest points' envelope), the weights summing to 1: n = Σ ∂d/∂x_a.
      ContactPairDerivatives jet;
      ContactPair& p = jet.pair;
      p = {.element = contact.element, .obstacle = m.obstacle(contact), .node_count = K};
      for (int a = 0; a < K; ++a) {
        p.normal += g.template segment<3>(3 * a);
        jet.normal.leftCols<N>() += h.template middleRows<3>(3 * a);
      }
      const std::array<int, K> nodes = m.element_nodes<K>(contact.element);
      for (int a = 0; a < K; ++a) {
        p.nodes[a] = nodes[a];
        p.weights[a] = g.template segment<3>(3 * a).dot(p.normal);
        jet.weights.row(a).leftCols<N>() =
            p.normal.transpose() * h.template middleRows<3>(3 * a) +
            g.template segment<3>(3 * a).transpose() * jet.normal.leftCols<N>();
      }
      const BarrierValue b = barrier(d, distance_);
      p.force = stiffness_ * std::abs(b.first);  // b′ < 0 below d̂: λ = −κ b′
      jet.force.leftCols<N>() = -stiffness_ * b.second * g.transpose();
      out.push_back(jet);
    });
  });
  return out;
}

std::array<int, 2> ObstacleContact::first_intersection(const Positions& x) const {
  const Impl& m = *impl_;
  for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t) {
    const auto& tri = m.triangles[t];
    const Vec3 a = node(x, tri[0]), b = node(x, tri[1]), c = node(x, tri[2]);
    // Obstacles that ignore one of its nodes (gripped by their end effector) may hold it.
    const auto ignores = [&](int obstacle) { return m.ignores_any(obstacle, tri); };
    for (const Plane& plane : m.planes)
      for (const Vec3& p : {a, b, c})
        if (!ignores(plane.obstacle) && !((p - plane.h.point).dot(plane.h.normal) > 0))
          return {plane.obstacle, t};
    const Aabb box = box_of({a, b, c}, 0);
    int found = -1;
    m.triangle_bvh.query(box, [&](int i) {
      if (found >= 0) return;
      const Triangle& o = m.obstacle_triangles[i];
      if (ignores(o.obstacle)) return;
      // Two triangles meet where an edge of one meets the other.
      const std::array<Vec3, 3> A{a, b, c}, B{o.a, o.b, o.c};
      for (int k = 0; k < 3 && found < 0; ++k)
        if (segment_triangle_distance(A[k], A[(k + 1) % 3], o.a, o.b, o.c) <= o.radius ||
            segment_triangle_distance(B[k], B[(k + 1) % 3], a, b, c) <= o.radius)
          found = o.obstacle;
    });
    m.segment_bvh.query(box, [&](int i) {
      const Segment& s = m.segments[i];
      if (found < 0 && !ignores(s.obstacle) &&
          segment_triangle_distance(s.a, s.b, a, b, c) <= s.radius)
        found = s.obstacle;
    });
    m.point_bvh.query(box, [&](int i) {
      const Point& q = m.points[i];
      if (found < 0 && !ignores(q.obstacle) &&
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
