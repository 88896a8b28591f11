#include <shapectl/contact/self_contact.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <shapectl/contact/barrier.hpp>
#include <shapectl/contact/bvh.hpp>
#include <shapectl/contact/point_triangle_distance.hpp>
#include <shapectl/contact/segment_segment_distance.hpp>
#include <shapectl/contact/segment_triangle_distance.hpp>
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
  std::vector<std::uint64_t> left_out;  // keys of the pairs closer than d̂ at rest, sorted

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

  std::array<Vec3, 4> positions(const Pair& p, const Positions& x) const {
    const std::array<int, 4> n = nodes(p);
    return {node(x, n[0]), node(x, n[1]), node(x, n[2]), node(x, n[3])};
  }

  // Calls visit(pair) for every pair sharing no node, not left out, whose boxes come within
  // `reach`: at x, or swept from x to x + dx if dx is given.
  template <class Visit>
  void for_each_candidate(const Positions& x, const Eigen::VectorXd* dx, double reach,
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
    const auto kept = [&](const Pair& p) {
      return !std::binary_search(left_out.begin(), left_out.end(), p.key());
    };
    for (int v : vertices)
      triangle_bvh.query(box({v}).inflated(reach), [&](int t) {
        const auto& tri = triangles[t];
        if (tri[0] == v || tri[1] == v || tri[2] == v) return;
        const Pair p{false, v, t};
        if (kept(p)) visit(p);
      });
    for (int e = 0; e < static_cast<int>(edges.size()); ++e)
      edge_bvh.query(edge_boxes[e].inflated(reach), [&](int f) {
        if (f <= e) return;
        const auto &a = edges[e], &b = edges[f];
        if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) return;
        const Pair p{true, e, f};
        if (kept(p)) visit(p);
      });
  }

  // The pairs closer than d̂ at x, in key order.
  std::vector<Pair> active(const Positions& x, double dhat) const {
    std::vector<Pair> pairs;
    for_each_candidate(x, nullptr, dhat, [&](const Pair& p) {
      if (distance(p, positions(p, x)) < dhat) pairs.push_back(p);
    });
    std::sort(pairs.begin(), pairs.end(),
              [](const Pair& a, const Pair& b) { return a.key() < b.key(); });
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
  // Neighbours at rest: left out for good (with none left out yet, active() lists them).
  for (const Pair& p : m->active(mesh.rest_vector(), distance)) m->left_out.push_back(p.key());
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
  m.for_each_candidate(x, nullptr, distance_, [&](const Pair& p) {
    const double d = Impl::distance(p, m.positions(p, x));
    if (!(d > 0)) intersecting = true;
    else if (d < distance_) sum += barrier(d, distance_).value;
  });
  return intersecting ? kInf : stiffness_ * sum;
}

void SelfContact::add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  const Impl& m = *impl_;
  m.for_each_candidate(x, nullptr, distance_, [&](const Pair& p) {
    VecN<N> g;
    const double d = Impl::distance(p, m.positions(p, x), &g);
    if (!(d < distance_)) return;
    // The gradient is NaN where the energy is +inf.
    const double scale = d > 0 ? stiffness_ * barrier(d, distance_).first : kNaN;
    const std::array<int, 4> nodes = m.nodes(p);
    for (int a = 0; a < 4; ++a) gradient.segment<3>(3 * nodes[a]) += scale * g.segment<3>(3 * a);
  });
}

void SelfContact::hessian_elements(const Positions& x, ElementNodes& elements) const {
  for (const Pair& p : impl_->active(x, distance_)) {
    const std::array<int, 4> n = impl_->nodes(p);
    elements.add({n[0], n[1], n[2], n[3]});
  }
}

void SelfContact::add_hessian(const Positions& x, ElementHessianSink& sink,
                              bool project_psd) const {
  const Impl& m = *impl_;
  const std::vector<Pair> pairs = m.active(x, distance_);  // hessian_elements(x)'s, in its order
  sink.add_blocks([&](std::size_t e, double* block) {
    VecN<N> g;
    MatN<N> h;
    const double d = Impl::distance(pairs[e], m.positions(pairs[e], x), &g, &h);
    if (!(d > 0)) {  // intersecting: a NaN block, so the factorization fails
      std::fill(block, block + N * N, kNaN);
      return;
    }
    const BarrierValue b = barrier(d, distance_);
    MatN<N> H = stiffness_ * (b.second * g * g.transpose() + b.first * h);
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
  m.for_each_candidate(x, &dx, distance_, [&](const Pair& p) {
    const std::array<int, 4> nodes = m.nodes(p);
    std::array<Vec3, 4> at = m.positions(p, x);
    const double d0 = Impl::distance(p, at);
    if (!(d0 > 0)) return;  // already intersecting: no step keeps it out
    const double target = 0.1 * d0;
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
  for (const Pair& p : impl_->active(x, distance_))
    smallest = std::min(smallest, Impl::distance(p, impl_->positions(p, x)));
  return smallest;
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
