#include <shapectl/contact/self_contact.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <shapectl/contact/barrier.hpp>
#include <shapectl/contact/bvh.hpp>
#include <shapectl/contact/edge_mollifier.hpp>
#include <shapectl/contact/point_triangle_distance.hpp>
#include <shapectl/contact/segment_segment_distance.hpp>
#include <shapectl/contact/segment_triangle_distance.hpp>
#include <shapectl/contact/separation.hpp>
#include <shapectl/contact/triangle_edges.hpp>

namespace shapectl {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int N = 12;  // a pair's 4 nodes' coordinates

// A vertex (node id) and a surface triangle, or two surface edges (a < b). Packed in 64 bits,
// so sorting gives one order of pairs for one set of pairs, whatever found them first.
struct Pair {
  bool edge_edge;
  int a, b;
  std::uint64_t key() const {
    return (std::uint64_t(edge_edge) << 62) | (std::uint64_t(a) << 31) | std::uint64_t(b);
  }
};

Vec3 node(const Positions& x, int i) { return x.segment<3>(3 * i); }

// Whether a pair whose distance is at least `bound` (separation.hpp) is surely farther apart than
// `reach`: with room for the bound's round-off (~1e-16 of the coordinates, in metres).
bool surely_beyond(double bound, double reach) { return bound > reach * (1 + 1e-9) + 1e-12; }

Aabb box_of(std::initializer_list<Vec3> points) {
  Aabb box;
  for (const Vec3& p : points) box.extend(p);
  return box;
}

}  // namespace

struct SelfContact::Impl {
  std::vector<int> vertices;  // node ids
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::uint64_t> left_out;    // keys of the pairs closer than d̂ at rest, sorted
  std::vector<double> edge_rest_length2;  // |edge|² at rest, for the mollifier's threshold

  std::array<int, 4> nodes(const Pair& p) const {
    if (p.edge_edge) return {edges[p.a][0], edges[p.a][1], edges[p.b][0], edges[p.b][1]};
    return {p.a, triangles[p.b][0], triangles[p.b][1], triangles[p.b][2]};
  }

  // The pair's distance with its nodes at `at`; gradient and Hessian if asked (may be null).
  static double distance(const Pair& p, const std::array<Vec3, 4>& at, VecN<N>* g = nullptr,
                         MatN<N>* h = nullptr) {
    constexpr std::array<bool, 4> all{true, true, true, true};
    if (p.edge_edge) return segment_segment_distance<N>(at[0], at[1], at[2], at[3], all, g, h);
    return point_triangle_distance<N>(at[0], at[1], at[2], at[3], all, g, h);
  }

  // The pair's mollifier with its nodes at `at` (edge_mollifier.hpp; 1 for a vertex–triangle
  // pair); gradient and Hessian if asked (may be null).
  double mollifier(const Pair& p, const std::array<Vec3, 4>& at, VecN<N>* g = nullptr,
                   MatN<N>* h = nullptr) const {
    if (!p.edge_edge) {
      if (g) g->setZero();
      if (h) h->setZero();
      return 1;
    }
    const double threshold =
        contact::edge_mollifier_threshold(edge_rest_length2[p.a], edge_rest_length2[p.b]);
    return contact::edge_mollifier<N>(at, {true, true, true, true}, threshold, g, h);
  }

  std::array<Vec3, 4> positions(const Pair& p, const Positions& x) const {
    const std::array<int, 4> n = nodes(p);
    return {node(x, n[0]), node(x, n[1]), node(x, n[2]), node(x, n[3])};
  }

  // A lower bound on the pair's distance at x, far cheaper than distance().
  double separation(const Pair& p, const Positions& x) const {
    const std::array<Vec3, 4> at = positions(p, x);
    return p.edge_edge ? segment_segment_separation(at[0], at[1], at[2], at[3])
                       : point_triangle_separation(at[0], at[1], at[2], at[3]);
  }

  bool kept(const Pair& p) const {
    return !std::binary_search(left_out.begin(), left_out.end(), p.key());
  }

  // Calls visit(pair) for every pair sharing no node whose boxes come within `reach`: at x, or
  // swept from x to x + dx if dx is given. Two BVHs built at x: the dear part.
  template <class Visit>
  void for_each_box_pair(const Positions& x, const Eigen::VectorXd* dx, double reach,
                         Visit&& visit) const {
    const auto box = [&](std::initializer_list<int> ids) {
      Aabb b;
      for (int i : ids) {
        b.extend(node(x, i));
        if (dx) b.extend(Vec3(node(x, i) + dx->segment<3>(3 * i)));
      }
      return b;
    };
    std::vector<Aabb> triangle_boxes, edge_boxes;
    for (const auto& t : triangles) triangle_boxes.push_back(box({t[0], t[1], t[2]}));
    for (const auto& e : edges) edge_boxes.push_back(box({e[0], e[1]}));
    const Bvh triangle_bvh(triangle_boxes), edge_bvh(edge_boxes);
    for (int v : vertices)
      triangle_bvh.query(box({v}).inflated(reach), [&](int t) {
        const auto& tri = triangles[t];
        if (tri[0] == v || tri[1] == v || tri[2] == v) return;
        visit(Pair{false, v, t});
      });
    for (int e = 0; e < static_cast<int>(edges.size()); ++e)
      edge_bvh.query(edge_boxes[e].inflated(reach), [&](int f) {
        if (f <= e) return;
        const auto &a = edges[e], &b = edges[f];
        if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) return;
        visit(Pair{true, e, f});
      });
  }

  // The pairs (sharing no node, not left out) that may be within `reach` of each other at x,
  // sorted: those whose cheap lower bound is within reach.
  std::vector<Pair> near(const Positions& x, double reach) const {
    std::vector<Pair> pairs;
    for_each_box_pair(x, nullptr, reach, [&](const Pair& p) {
      if (kept(p) && !surely_beyond(separation(p, x), reach)) pairs.push_back(p);
    });
    std::sort(pairs.begin(), pairs.end(),
              [](const Pair& a, const Pair& b) { return a.key() < b.key(); });
    return pairs;
  }

  // The near pairs at `reference` for a reach of d̂ + 2 margin: while no surface node is farther
  // than `margin` from there, no pair's distance has fallen by more than 2 margin, so every pair
  // within d̂ is among them. Found once for the many calls of a Newton solve at nearby states.
  struct NearCache {
    Positions reference;
    double margin = 0;
    std::vector<Pair> pairs;
  };
  double dhat = 0;
  double margin = 0;  // NearCache's
  // The last few found: solves on several threads (at other joints) each keep theirs.
  static constexpr std::size_t kCaches = 4;
  mutable std::mutex cache_mutex;
  mutable std::array<std::shared_ptr<const NearCache>, kCaches> caches;
  mutable std::size_t next_cache = 0;  // the one replaced next

  // Whether no surface vertex of x is farther than `limit` from where it is in `reference`; the
  // farthest in `largest`.
  bool within(const Positions& x, const Positions& reference, double limit,
              double* largest = nullptr) const {
    if (x.size() != reference.size()) return false;
    double l = 0;
    for (int v : vertices) {
      l = std::max(l, (node(x, v) - node(reference, v)).norm());
      if (!(l <= limit)) return false;  // NaN too
    }
    if (largest) *largest = l;
    return true;
  }

  // A near cache valid at x (x within its margin of its reference), found anew if none is.
  std::shared_ptr<const NearCache> near_cache(const Positions& x, double* move) const {
    std::array<std::shared_ptr<const NearCache>, kCaches> known;
    {
      const std::lock_guard<std::mutex> lock(cache_mutex);
      known = caches;
    }
    for (const auto& c : known)
      if (c && within(x, c->reference, c->margin, move)) return c;
    // Found outside the lock: another thread may do the same meanwhile, to the same effect.
    auto fresh = std::make_shared<NearCache>(NearCache{x, margin, near(x, dhat + 2 * margin)});
    *move = 0;
    const std::lock_guard<std::mutex> lock(cache_mutex);
    caches[next_cache] = fresh;
    next_cache = (next_cache + 1) % kCaches;
    return fresh;
  }

  // Calls visit(pair), in key order, for every pair sharing no node, not left out, that may be
  // within d̂ at x: a superset of those within d̂ (others are farther than d̂ and add nothing).
  template <class Visit>
  void for_each_candidate(const Positions& x, Visit&& visit) const {
    double move = 0;
    const std::shared_ptr<const NearCache> c = near_cache(x, &move);
    for (const Pair& p : c->pairs)
      if (!surely_beyond(separation(p, x), dhat)) visit(p);
  }

  // Calls visit(pair) for every pair sharing no node, not left out, whose boxes swept from x to
  // x + dx come within d̂ (the pairs whose CCD may bound the step). A short step tries only the
  // near pairs: any other is farther apart than d̂ + 2 (margin − move) at x (move: x's from the
  // near pairs' reference), its gap falls by at most l ≤ twice the longest node step, so while
  // that is at most 0.8 of it, its CCD's first advance (0.9 d0 / l) passes the whole step: it
  // bounds nothing. A longer step: BVHs over the swept boxes.
  template <class Visit>
  void for_each_swept_candidate(const Positions& x, const Eigen::VectorXd& dx,
                                Visit&& visit) const {
    double move = 0;
    const std::shared_ptr<const NearCache> c = near_cache(x, &move);
    double longest = 0;
    for (int v : vertices) longest = std::max(longest, dx.segment<3>(3 * v).norm());
    if (!(2 * longest <= 0.8 * (dhat + 2 * (c->margin - move)))) {
      for_each_box_pair(x, &dx, dhat, [&](const Pair& p) {
        if (kept(p)) visit(p);
      });
      return;
    }
    // The boxes and their test as for_each_box_pair's.
    const auto box = [&](std::initializer_list<int> ids) {
      Aabb b;
      for (int i : ids) {
        b.extend(node(x, i));
        b.extend(Vec3(node(x, i) + dx.segment<3>(3 * i)));
      }
      return b;
    };
    for (const Pair& p : c->pairs) {
      const std::array<int, 4> n = nodes(p);
      const bool overlap = p.edge_edge
                               ? box({n[0], n[1]}).inflated(dhat).overlaps(box({n[2], n[3]}))
                               : box({n[0]}).inflated(dhat).overlaps(box({n[1], n[2], n[3]}));
      if (overlap) visit(p);
    }
  }

  // The pairs closer than d̂ at x, in key order.
  std::vector<Pair> active(const Positions& x) const {
    std::vector<Pair> pairs;
    for_each_candidate(x, [&](const Pair& p) {
      if (distance(p, positions(p, x)) < dhat) pairs.push_back(p);
    });
    return pairs;
  }
};

SelfContact::SelfContact(const TetMesh& mesh, double distance, double stiffness)
    : distance_(distance), stiffness_(stiffness) {
  check_barrier_parameters("SelfContact", distance, stiffness);
  auto m = std::make_shared<Impl>();
  m->triangles = mesh.surface_triangles();
  m->edges = triangle_edges(m->triangles);
  m->vertices = triangle_corners(m->triangles);
  const Positions rest = mesh.rest_vector();
  // A quarter of the shortest surface edge: at rest, pairs of a flat stretch of surface are
  // farther apart than d̂ + 2 margin (their distance is about an edge length), so the near
  // pairs are few while nothing touches, and the statics' steps seldom move a node that far.
  double shortest = kInf;
  for (const auto& e : m->edges)
    shortest = std::min(shortest, (node(rest, e[0]) - node(rest, e[1])).norm());
  for (const auto& e : m->edges)
    m->edge_rest_length2.push_back((node(rest, e[1]) - node(rest, e[0])).squaredNorm());
  m->dhat = distance;
  m->margin = std::isfinite(shortest) ? 0.25 * shortest : 0.0;
  // Neighbours at rest (within d̂ there) are left out for good; the other near pairs at rest
  // serve the first states, usually the rest shape or close to it.
  std::vector<Pair> near = m->near(rest, distance + 2 * m->margin);
  for (const Pair& p : near)
    if (Impl::distance(p, m->positions(p, rest)) < distance) m->left_out.push_back(p.key());
  near.erase(std::remove_if(near.begin(), near.end(), [&](const Pair& p) { return !m->kept(p); }),
             near.end());
  m->caches[0] =
      std::make_shared<Impl::NearCache>(Impl::NearCache{rest, m->margin, std::move(near)});
  m->next_cache = 1;
  impl_ = std::move(m);
}

SelfContact SelfContact::scaled(double factor) const {
  SelfContact out = *this;
  out.stiffness_ *= factor;
  check_barrier_parameters("SelfContact", distance_, out.stiffness_);
  return out;
}

double SelfContact::value(const Positions& x) const {
  const Impl& m = *impl_;
  double sum = 0;
  bool intersecting = false;
  m.for_each_candidate(x, [&](const Pair& p) {
    const std::array<Vec3, 4> at = m.positions(p, x);
    const double d = Impl::distance(p, at);
    if (!(d > 0)) intersecting = true;
    else if (d < distance_) sum += barrier(d, distance_).value * m.mollifier(p, at);
  });
  return intersecting ? kInf : stiffness_ * sum;
}

void SelfContact::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const Impl& m = *impl_;
  m.for_each_candidate(x, [&](const Pair& p) {
    const std::array<Vec3, 4> at = m.positions(p, x);
    VecN<N> g, gm;
    const double d = Impl::distance(p, at, &g);
    if (!(d < distance_)) return;
    if (d > 0) {  // ∇(b e) = e b′ ∇d + b ∇e
      const BarrierValue b = barrier(d, distance_);
      g = stiffness_ * (m.mollifier(p, at, &gm) * b.first * g + b.value * gm);
    } else {
      g.setConstant(kNaN);  // the gradient is NaN where the energy is +inf
    }
    const std::array<int, 4> nodes = m.nodes(p);
    for (int a = 0; a < 4; ++a) gradient.segment<3>(3 * nodes[a]) += g.segment<3>(3 * a);
  });
}

void SelfContact::hessian_elements(const Positions& x, ElementNodes& elements) const {
  for (const Pair& p : impl_->active(x)) {
    const std::array<int, 4> n = impl_->nodes(p);
    elements.add({n[0], n[1], n[2], n[3]});
  }
}

void SelfContact::add_hessian(const Positions& x, ElementHessianSink& sink,
                              bool project_psd) const {
  const Impl& m = *impl_;
  const std::vector<Pair> pairs = m.active(x);  // hessian_elements(x)'s, in its order
  sink.add_blocks([&](std::size_t e, double* block) {
    const std::array<Vec3, 4> at = m.positions(pairs[e], x);
    VecN<N> g, gm;
    MatN<N> h, hm;
    const double d = Impl::distance(pairs[e], at, &g, &h);
    if (!(d > 0)) {  // intersecting: a NaN block, so the factorization fails
      std::fill(block, block + N * N, kNaN);
      return;
    }
    const BarrierValue b = barrier(d, distance_);
    const double mollifier = m.mollifier(pairs[e], at, &gm, &hm);
    // ∇²(b e) = e (b″ ∇d ∇dᵀ + b′ ∇²d) + b′ (∇d ∇eᵀ + ∇e ∇dᵀ) + b ∇²e
    MatN<N> H = stiffness_ * (mollifier * (b.second * g * g.transpose() + b.first * h) +
                              b.first * (g * gm.transpose() + gm * g.transpose()) + b.value * hm);
    if (project_psd) {
      Eigen::SelfAdjointEigenSolver<MatN<N>> eig(H);
      H = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
          eig.eigenvectors().transpose();
    }
    Eigen::Map<MatN<N>>{block} = H;
  });
}

double SelfContact::max_step(const Positions& x, const Eigen::VectorXd& dx) const {
  const Impl& m = *impl_;
  double alpha = 1;
  m.for_each_swept_candidate(x, dx, [&](const Pair& p) {
    const std::array<int, 4> nodes = m.nodes(p);
    // Additive CCD (Li et al. 2021): the gap changes no faster than the largest displacement
    // of one primitive's nodes plus the other's, l, so from t with gap d it stays ≥ target up
    // to t + (d − target)/l.
    const int first_of_b = p.edge_edge ? 2 : 1;
    double la = 0, lb = 0;
    for (int k = 0; k < 4; ++k) {
      const double s = dx.segment<3>(3 * nodes[k]).norm();
      (k < first_of_b ? la : lb) = std::max(k < first_of_b ? la : lb, s);
    }
    const double l = la + lb;
    if (!(l > 0)) return;
    // Its first advance, 0.9 d0 / l, would pass the whole step: nothing to bound (the cheap
    // lower bound on d0 says so for most candidates without their exact distance).
    if (surely_beyond(0.9 * m.separation(p, x), l)) return;
    std::array<Vec3, 4> at = m.positions(p, x);
    const double d0 = Impl::distance(p, at);
    if (!(d0 > 0)) return;  // already intersecting: no step keeps it out
    const double target = 0.1 * d0;
    double t = 0, d = d0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      t += (d - target) / l;
      if (t >= alpha) return;
      for (int k = 0; k < 4; ++k) at[k] = node(x, nodes[k]) + t * dx.segment<3>(3 * nodes[k]);
      d = Impl::distance(p, at);
      // Close enough to the target: further steps would shrink geometrically.
      if (d - target <= 0.1 * (d0 - target)) break;
    }
    alpha = std::min(alpha, t);
  });
  return alpha;
}

double SelfContact::min_distance(const Positions& x) const {
  double smallest = kInf;
  for (const Pair& p : impl_->active(x))
    smallest = std::min(smallest, Impl::distance(p, impl_->positions(p, x)));
  return smallest;
}

SelfContactSummary SelfContact::summary(const Positions& x) const {
  const Impl& m = *impl_;
  SelfContactSummary out;
  for (const Pair& p : m.active(x)) {
    VecN<N> g;
    const std::array<Vec3, 4> at = m.positions(p, x);
    const double d = Impl::distance(p, at, &g);
    // ∂d/∂x of the first primitive's nodes are their closest-point weights times the unit
    // normal n from the second towards it (envelope theorem): its closest point is Σ w x, the
    // other's that less d n.
    const int first = p.edge_edge ? 2 : 1;
    Vec3 n = Vec3::Zero();
    for (int k = 0; k < first; ++k) n += g.segment<3>(3 * k);
    Vec3 closest = Vec3::Zero();
    for (int k = 0; k < first; ++k) closest += g.segment<3>(3 * k).dot(n) * at[k];
    // Touching (d = 0: no normal): the first primitive's first node.
    const bool normal = d > 0 && n.allFinite() && closest.allFinite();
    out.points.push_back(normal ? Vec3(closest - 0.5 * d * n) : at[0]);
    out.distances.push_back(d);
    out.min_distance = std::min(out.min_distance, d);
  }
  out.count = static_cast<int>(out.points.size());
  return out;
}

std::array<int, 2> SelfContact::first_intersection(const Positions& x) const {
  const Impl& m = *impl_;
  std::vector<Aabb> boxes;
  for (const auto& t : m.triangles)
    boxes.push_back(box_of({node(x, t[0]), node(x, t[1]), node(x, t[2])}));
  const Bvh bvh(boxes);
  for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t) {
    const auto& A = m.triangles[t];
    int found = -1;
    bvh.query(boxes[t], [&](int u) {
      const auto& B = m.triangles[u];
      if (found >= 0 || u <= t) return;
      for (int i : A)
        if (i == B[0] || i == B[1] || i == B[2]) return;
      // Two triangles meet where an edge of one meets the other.
      const std::array<Vec3, 3> a{node(x, A[0]), node(x, A[1]), node(x, A[2])},
          b{node(x, B[0]), node(x, B[1]), node(x, B[2])};
      if (surely_beyond(triangle_triangle_separation(a, b), 0)) return;
      for (int k = 0; k < 3 && found < 0; ++k)
        if (segment_triangle_distance(a[k], a[(k + 1) % 3], b[0], b[1], b[2]) <= 0 ||
            segment_triangle_distance(b[k], b[(k + 1) % 3], a[0], a[1], a[2]) <= 0)
          found = u;
    });
    if (found >= 0) return {t, found};
  }
  return {-1, -1};
}

}  // namespace shapectl
