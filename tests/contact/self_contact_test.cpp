// The object's contact with itself: derivatives against central differences for vertex–triangle
// and edge–edge pairs, PSD projection, the pairs left out (sharing a node, neighbours at rest),
// CCD and the intersection query. The object: two tetrahedra, far apart at rest, brought close.
#include <shapectl/contact/self_contact.hpp>

#include <gtest/gtest.h>

#include <shapectl/contact/edge_mollifier.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <shapectl/mesh/box_mesh.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

constexpr double kDhat = 0.01;  // large enough that central differences (h = 1e-6) resolve b

// Tet A: the corner (0,0,0), (0.1,0,0), (0,0.1,0), (0,0,0.1); tet B: `b` (any orientation),
// placed 1 m away at rest so that no pair is a neighbour there.
TetMesh two_tets(std::array<Vec3, 4> b) {
  std::vector<Vec3> p{{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}};
  if ((b[1] - b[0]).cross(b[2] - b[0]).dot(b[3] - b[0]) < 0) std::swap(b[2], b[3]);
  for (const Vec3& q : b) p.push_back(q + Vec3(1, 0, 0));
  return TetMesh(p, {{0, 1, 2, 3}, {4, 5, 6, 7}});
}

// B where it is meant to be (its rest shifted back by 1 m), every node moved by up to 1e-3 m
// (a generic configuration: no symmetry hides an error).
Positions brought_close(const TetMesh& mesh, unsigned seed, double by = 1e-3) {
  Positions x = mesh.rest_vector();
  for (int i = 4; i < 8; ++i) x[3 * i] -= 1;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-by, by);
  for (int i = 0; i < x.size(); ++i) x[i] += u(rng);
  return x;
}

// B's apex 5 mm below the middle of A's bottom face: vertex–triangle pairs only.
TetMesh vertex_triangle() {
  return two_tets({Vec3(0.02, 0.02, -0.005), Vec3(0.0, 0.0, -0.1), Vec3(0.08, 0.0, -0.1),
                   Vec3(0.0, 0.08, -0.1)});
}

// B's top edge 5 mm below A's bottom face, across its edges on y = 0 and x + y = 0.1, its ends
// far outside: edge–edge pairs only.
TetMesh edge_edge() {
  return two_tets({Vec3(0.05, -0.1, -0.005), Vec3(0.05, 0.2, -0.005), Vec3(0.0, 0.05, -0.1),
                   Vec3(0.1, 0.05, -0.08)});
}

Eigen::MatrixXd dense_hessian(const EnergyTerm& term, const Positions& x, bool project) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(x.size(), x.size());
  for (const auto& t : term.hessian_triplets(x, project)) H(t.row(), t.col()) += t.value();
  return H;
}

// How many of the active pairs are vertex–triangle (one node of B, three of A, or the other
// way) and edge–edge (two of each).
std::array<int, 2> pair_kinds(const SelfContact& term, const Positions& x) {
  ElementNodes elements;
  term.hessian_elements(x, elements);
  std::array<int, 2> kinds{0, 0};
  for (std::size_t e = 0; e < elements.size(); ++e) {
    EXPECT_EQ(elements.node_count(e), 4);
    int of_b = 0;
    for (int k = 0; k < 4; ++k) of_b += elements.begin(e)[k] >= 4;
    ++kinds[of_b == 2 ? 1 : 0];
  }
  return kinds;
}

void expect_derivatives_match(const TetMesh& mesh, unsigned seed, double by = 1e-3) {
  const SelfContact term(mesh, kDhat, 3.0);
  const Positions x = brought_close(mesh, seed, by);
  ASSERT_TRUE(std::isfinite(term.value(x)));
  ASSERT_GT(term.value(x), 0);
  const auto gradient_at = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(y.size());
    term.add_gradient(y, g);
    return g;
  };
  const Eigen::VectorXd g = gradient_at(x);
  EXPECT_TRUE(test::derivative_matches(
      g,
      test::central_difference_gradient([&](const Eigen::VectorXd& y) { return term.value(y); }, x,
                                        1e-6),
      1e-5, "gradient"));
  EXPECT_TRUE(test::derivative_matches(dense_hessian(term, x, false),
                                       test::central_difference_jacobian(gradient_at, x, 1e-6),
                                       1e-5, "Hessian"));
  // Projected: each block PSD, so the sum is.
  const Eigen::MatrixXd P = dense_hessian(term, x, true);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff(),
            -1e-9 * P.norm());
}

TEST(SelfContact, VertexTriangleDerivativesMatchCentralDifferences) {
  const TetMesh mesh = vertex_triangle();
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto kinds = pair_kinds(SelfContact(mesh, kDhat, 3.0), brought_close(mesh, seed));
    EXPECT_GE(kinds[0], 1);
    EXPECT_EQ(kinds[1], 0);
    expect_derivatives_match(mesh, seed);
  }
}

TEST(SelfContact, EdgeEdgeDerivativesMatchCentralDifferences) {
  const TetMesh mesh = edge_edge();
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto kinds = pair_kinds(SelfContact(mesh, kDhat, 3.0), brought_close(mesh, seed));
    EXPECT_EQ(kinds[0], 0);
    EXPECT_GE(kinds[1], 2) << "B's edge crosses two of A's";
    expect_derivatives_match(mesh, seed);
  }
}

// B's top edge, 6 cm long, 5.8 mm beside and below A's edge along x (10 cm), at an angle whose
// sine is `sine` (about z): the mollifier's c/ε is 1000 sine².
TetMesh nearly_parallel(double sine) {
  const Vec3 a(0.02, -0.005, -0.003);
  const Vec3 b = a + 0.06 * Vec3(std::sqrt(1 - sine * sine), sine, 0);
  return two_tets({a, b, Vec3(0.05, -0.06, -0.1), Vec3(0.03, -0.1, -0.08)});
}

// The mollifier alone, against central differences of its value and gradient, from edges
// nearly parallel (c ≪ ε) to across ε and beyond (e = 1: zero derivatives).
TEST(SelfContact, EdgeMollifierDerivativesMatchCentralDifferences) {
  for (double ratio : {0.02, 0.4, 0.97, 1.03, 3.0}) {
    const double sine = std::sqrt(ratio / 1000);
    const std::array<Vec3, 4> p{Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.02, -0.005, -0.003),
                                Vec3(0.02, -0.005, -0.003) + 0.06 * Vec3(std::sqrt(1 - sine * sine),
                                                                         sine * 0.8, sine * 0.6)};
    const double eps = contact::edge_mollifier_threshold(0.01, 0.0036);
    constexpr std::array<bool, 4> all{true, true, true, true};
    Eigen::VectorXd x(12);
    for (int k = 0; k < 4; ++k) x.segment<3>(3 * k) = p[k];
    const auto points = [](const Eigen::VectorXd& y) {
      return std::array<Vec3, 4>{y.segment<3>(0), y.segment<3>(3), y.segment<3>(6),
                                 y.segment<3>(9)};
    };
    const auto value = [&](const Eigen::VectorXd& y) {
      return contact::edge_mollifier<12>(points(y), all, eps, nullptr, nullptr);
    };
    const auto gradient = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
      VecN<12> g;
      contact::edge_mollifier<12>(points(y), all, eps, &g, nullptr);
      return g;
    };
    VecN<12> g;
    MatN<12> h;
    const double e = contact::edge_mollifier<12>(p, all, eps, &g, &h);
    const double c = ((p[1] - p[0]).cross(p[3] - p[2])).squaredNorm();
    EXPECT_NEAR(c / eps, ratio, 1e-6 * ratio);
    EXPECT_NEAR(e, ratio < 1 ? -ratio * ratio + 2 * ratio : 1.0, 1e-12) << "c/ε " << ratio;
    if (ratio > 1) {
      EXPECT_EQ(g.norm(), 0.0);
      EXPECT_EQ(h.norm(), 0.0);
      continue;
    }
    // h relative to the coordinates (0.1 m): the differences stay on one side of ε.
    EXPECT_TRUE(test::derivative_matches(g, test::central_difference_gradient(value, x, 1e-8), 1e-5,
                                         "mollifier gradient"))
        << "c/ε " << ratio;
    EXPECT_TRUE(test::derivative_matches(h, test::central_difference_jacobian(gradient, x, 1e-8),
                                         1e-5, "mollifier Hessian"))
        << "c/ε " << ratio;
  }
}

// The whole term (the product rule of barrier and mollifier) with a pair of nearly parallel
// edges within d̂, below ε and just across it.
TEST(SelfContact, NearlyParallelEdgesDerivativesMatchCentralDifferences) {
  for (double ratio : {0.05, 0.4, 0.9, 1.2}) {
    const TetMesh mesh = nearly_parallel(std::sqrt(ratio / 1000));
    const auto kinds = pair_kinds(SelfContact(mesh, kDhat, 3.0), brought_close(mesh, 1, 1e-6));
    EXPECT_GE(kinds[1], 1) << "edge–edge pairs";
    expect_derivatives_match(mesh, 1, 1e-6);
  }
}

TEST(SelfContact, IsZeroAndHasNoPairsAtRestEvenOnAMeshThinnerThanDhat) {
  // 5 mm thick, d̂ = 10 mm: its top and bottom faces are neighbours at rest, left out.
  const TetMesh thin = make_box_mesh({0.1, 0.1, 0.005}, {4, 4, 1});
  const SelfContact term(thin, kDhat, 3.0);
  const Positions x = thin.rest_vector();
  EXPECT_EQ(term.value(x), 0.0);
  ElementNodes elements;
  term.hessian_elements(x, elements);
  EXPECT_EQ(elements.size(), 0u);
  EXPECT_EQ(term.first_intersection(x)[0], -1);
  // The two far tets at rest: nothing either.
  const TetMesh two = vertex_triangle();
  EXPECT_EQ(SelfContact(two, kDhat, 3.0).value(two.rest_vector()), 0.0);
}

TEST(SelfContact, ElementsFollowTheState) {
  const TetMesh mesh = vertex_triangle();
  const SelfContact term(mesh, kDhat, 3.0);
  ElementNodes at_rest, close, again;
  term.hessian_elements(mesh.rest_vector(), at_rest);
  const Positions x = brought_close(mesh, 1);
  term.hessian_elements(x, close);
  term.hessian_elements(x, again);
  EXPECT_EQ(at_rest.size(), 0u);
  EXPECT_GT(close.size(), 0u);
  EXPECT_EQ(close, again) << "one state, one list of elements in one order";
}

TEST(SelfContact, MaxStepStopsBeforeTheSurfacesPassThroughEachOther) {
  const TetMesh mesh = vertex_triangle();
  const SelfContact term(mesh, kDhat, 3.0);
  const Positions x = brought_close(mesh, 2);
  ASSERT_EQ(term.first_intersection(x)[0], -1);
  // B moved 5 cm up: its apex would go through A's bottom face.
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(x.size());
  for (int i = 4; i < 8; ++i) dx[3 * i + 2] = 0.05;
  const Positions through = x + dx;
  EXPECT_GE(term.first_intersection(through)[0], 0) << "the full step intersects";
  const double alpha = term.max_step(x, dx);
  EXPECT_GT(alpha, 0);
  EXPECT_LT(alpha, 0.1);  // the apex is ~5 mm below: 10 % of 5 cm
  for (double s : {0.25, 0.5, 0.75, 1.0}) {
    const Positions y = x + s * alpha * dx;
    EXPECT_EQ(term.first_intersection(y)[0], -1);
    EXPECT_TRUE(std::isfinite(term.value(y)));
  }
  EXPECT_GT(term.min_distance(x + alpha * dx), 0);
}

// B where it is meant to be, unperturbed.
Positions placed(const TetMesh& mesh) {
  Positions x = mesh.rest_vector();
  for (int i = 4; i < 8; ++i) x[3 * i] -= 1;
  return x;
}

// Whether `points` holds p (to round-off).
bool holds(const std::vector<Vec3>& points, const Vec3& p) {
  return std::any_of(points.begin(), points.end(),
                     [&](const Vec3& q) { return (q - p).norm() < 1e-12; });
}

TEST(SelfContact, SummaryPlacesEachPairMidwayBetweenItsClosestPoints) {
  // B's apex 5 mm below A's bottom face (z = 0) at (0.02, 0.02): they meet 2.5 mm below it.
  const TetMesh apex = vertex_triangle();
  const SelfContact a(apex, kDhat, 3.0);
  const SelfContactSummary s = a.summary(placed(apex));
  ElementNodes elements;
  a.hessian_elements(placed(apex), elements);
  EXPECT_EQ(s.count, static_cast<int>(elements.size()));
  ASSERT_EQ(s.points.size(), elements.size());
  EXPECT_NEAR(s.min_distance, 0.005, 1e-15);
  EXPECT_EQ(s.min_distance, a.min_distance(placed(apex)));
  EXPECT_TRUE(holds(s.points, Vec3(0.02, 0.02, -0.0025)));
  // B's top edge, 5 mm below A's bottom face at x = 0.05, crosses A's edges on y = 0 and on
  // x + y = 0.1 there: two edge–edge pairs meeting 2.5 mm below them.
  const TetMesh edge = edge_edge();
  const SelfContact e(edge, kDhat, 3.0);
  const SelfContactSummary t = e.summary(placed(edge));
  EXPECT_NEAR(t.min_distance, 0.005, 1e-15);
  EXPECT_TRUE(holds(t.points, Vec3(0.05, 0.0, -0.0025)));
  EXPECT_TRUE(holds(t.points, Vec3(0.05, 0.05, -0.0025)));
  for (std::size_t k = 0; k < t.points.size(); ++k) {
    EXPECT_GE(t.distances[k], t.min_distance);
    EXPECT_LT(t.distances[k], kDhat);
  }
  // Nothing near: nothing listed.
  const SelfContactSummary none = e.summary(edge.rest_vector());
  EXPECT_EQ(none.count, 0);
  EXPECT_TRUE(none.points.empty());
  EXPECT_EQ(none.min_distance, std::numeric_limits<double>::infinity());
}

// The pairs a term finds are remembered across calls (near pairs kept while the surface moves
// less than a margin, a short step's CCD over them alone): a term used along a walk of states
// must answer exactly as a new term (which knows no earlier state) does at each.
TEST(SelfContact, ATermUsedAlongAWalkAnswersAsANewTermAtEachState) {
  for (const TetMesh& mesh : {vertex_triangle(), edge_edge()}) {
    const SelfContact walker(mesh, kDhat, 3.0);
    Positions x = brought_close(mesh, 4);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    int active = 0;
    for (int step = 0; step < 60; ++step) {
      // Steps from 0.1 mm to 3 cm: within a margin (2 cm here) and beyond it.
      const double size = 1e-4 * std::pow(300.0, (step % 7) / 6.0);
      Eigen::VectorXd dx(x.size());
      for (int i = 0; i < dx.size(); ++i) dx[i] = size * u(rng);
      const SelfContact fresh(mesh, kDhat, 3.0);
      ElementNodes mine, theirs;
      walker.hessian_elements(x, mine);
      fresh.hessian_elements(x, theirs);
      ASSERT_EQ(mine, theirs) << "step " << step;
      active += mine.size() > 0;
      EXPECT_EQ(walker.value(x), fresh.value(x)) << "step " << step;
      Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size()), h = g;
      walker.add_gradient(x, g);
      fresh.add_gradient(x, h);
      EXPECT_EQ(g, h) << "step " << step;
      const double alpha = walker.max_step(x, dx);
      EXPECT_EQ(alpha, SelfContact(mesh, kDhat, 3.0).max_step(x, dx)) << "step " << step;
      const Positions next = x + alpha * dx;
      if (walker.first_intersection(next)[0] < 0 && std::isfinite(walker.value(next))) x = next;
    }
    EXPECT_GT(active, 10) << "the walk stays in contact for a good part";
  }
}

}  // namespace
}  // namespace shapectl
