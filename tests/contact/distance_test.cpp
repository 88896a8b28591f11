// The primitive distances: values against brute-force sampling, exact gradients and Hessians
// against central differences in every region of IPC's classification.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <random>

#include <shapectl/contact/barrier.hpp>
#include <shapectl/contact/point_point_distance.hpp>
#include <shapectl/contact/point_segment_distance.hpp>
#include <shapectl/contact/point_triangle_distance.hpp>
#include <shapectl/contact/segment_segment_distance.hpp>

#include "support/derivative_check.hpp"

namespace shapectl {
namespace {

constexpr double kTolerance = 1e-5;
constexpr int kPerRegion = 6;

Vec3 random_point(std::mt19937& rng, double low, double high) {
  std::uniform_real_distribution<double> u(low, high);
  return {u(rng), u(rng), u(rng)};
}

// `points` stacked, the ones with varies[k] only, and back.
template <std::size_t K>
Eigen::VectorXd stack(const std::array<Vec3, K>& points, const std::array<bool, K>& varies) {
  Eigen::VectorXd v(0);
  for (std::size_t k = 0; k < K; ++k)
    if (varies[k]) {
      v.conservativeResize(v.size() + 3);
      v.tail<3>() = points[k];
    }
  return v;
}
template <std::size_t K>
std::array<Vec3, K> unstack(std::array<Vec3, K> points, const std::array<bool, K>& varies,
                            const Eigen::VectorXd& v) {
  int next = 0;
  for (std::size_t k = 0; k < K; ++k)
    if (varies[k]) {
      points[k] = v.segment<3>(next);
      next += 3;
    }
  return points;
}

// distance(points, gradient, hessian) with the points that vary as the variables: its gradient
// and Hessian against central differences of its value and gradient.
template <int N, std::size_t K, class Distance>
void expect_exact_derivatives(const Distance& distance, const std::array<Vec3, K>& points,
                              const std::array<bool, K>& varies, const std::string& what) {
  VecN<N> gradient;
  MatN<N> hessian;
  VecN<N>* const no_gradient = nullptr;
  MatN<N>* const no_hessian = nullptr;
  const double d = distance(points, &gradient, &hessian);
  VecN<N> gradient_only;
  // The same pieces in double and in jets: equal to rounding.
  EXPECT_NEAR(distance(points, &gradient_only, no_hessian), d, 1e-14 * d) << what;
  EXPECT_NEAR(distance(points, no_gradient, no_hessian), d, 1e-14 * d) << what;
  EXPECT_TRUE(((gradient_only - gradient).array() == 0).all()) << what;
  const Eigen::VectorXd x0 = stack(points, varies);
  const auto value = [&](const Eigen::VectorXd& x) {
    return distance(unstack(points, varies, x), no_gradient, no_hessian);
  };
  const auto grad = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    VecN<N> g;
    distance(unstack(points, varies, x), &g, no_hessian);
    return g;
  };
  EXPECT_TRUE(test::derivative_matches(gradient, test::central_difference_gradient(value, x0, 1e-6),
                                       kTolerance, what + " gradient"));
  const Eigen::MatrixXd reference = test::central_difference_jacobian(grad, x0, 1e-6);
  // A distance linear in its variables (a point moving against a plane) has none.
  if (reference.cwiseAbs().maxCoeff() < test::kDerivativeFloor)
    EXPECT_LT(hessian.cwiseAbs().maxCoeff(), 1e-12) << what;
  else EXPECT_TRUE(test::derivative_matches(hessian, reference, kTolerance, what + " Hessian"));
}

TEST(PointTriangleDistance, ValueIsTheSmallestOverTheTriangle) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 p = random_point(rng, -1, 2), a = random_point(rng, 0, 1),
               b = random_point(rng, 0, 1), c = random_point(rng, 0, 1);
    Vec3 closest;
    point_triangle_region(p, a, b, c, &closest);
    const double d = point_triangle_distance<0>(p, a, b, c, {false, false, false, false});
    EXPECT_NEAR(d, (p - closest).norm(), 1e-12);
    double sampled = 1e9;
    const int n = 60;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
        sampled = std::min(sampled, (p - (a + (b - a) * i / n + (c - a) * j / n)).norm());
    EXPECT_LE(d, sampled + 1e-12);
    EXPECT_GE(d, sampled - 0.05 * ((b - a).norm() + (c - a).norm()));
  }
}

TEST(PointTriangleDistance, DerivativesAreExactInEveryRegion) {
  std::mt19937 rng(2);
  std::map<PointTriangleRegion, int> checked;
  for (int trial = 0, done = 0; trial < 20000 && done < 7 * kPerRegion; ++trial) {
    const std::array<Vec3, 4> P{random_point(rng, -1, 2), random_point(rng, 0, 1),
                                random_point(rng, 0, 1), random_point(rng, 0, 1)};
    const PointTriangleRegion region = point_triangle_region(P[0], P[1], P[2], P[3]);
    if (checked[region] >= kPerRegion) continue;
    if (point_triangle_distance<0>(P[0], P[1], P[2], P[3], {false, false, false, false}) < 0.05)
      continue;
    ++checked[region];
    ++done;
    const std::string what = "region " + std::to_string(static_cast<int>(region));
    // The object's point moves (vertex against obstacle triangle), the object's triangle moves
    // (obstacle point against it), or everything does.
    const auto distance = [](const std::array<bool, 4>& varies) {
      return [varies](const std::array<Vec3, 4>& Q, auto* g, auto* h) {
        constexpr int N = std::remove_pointer_t<decltype(g)>::RowsAtCompileTime;
        return point_triangle_distance<N>(Q[0], Q[1], Q[2], Q[3], varies, g, h);
      };
    };
    const std::array<bool, 4> point{true, false, false, false}, triangle{false, true, true, true},
        all{true, true, true, true};
    expect_exact_derivatives<3>(distance(point), P, point, what + " (point varies)");
    expect_exact_derivatives<9>(distance(triangle), P, triangle, what + " (triangle varies)");
    expect_exact_derivatives<12>(distance(all), P, all, what + " (all vary)");
  }
  for (auto region : {PointTriangleRegion::A, PointTriangleRegion::B, PointTriangleRegion::C,
                      PointTriangleRegion::AB, PointTriangleRegion::BC, PointTriangleRegion::CA,
                      PointTriangleRegion::Face})
    EXPECT_EQ(checked[region], kPerRegion) << "region " << static_cast<int>(region);
}

TEST(SegmentSegmentDistance, ValueIsTheSmallestOverBothSegments) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a0 = random_point(rng, 0, 1), a1 = random_point(rng, 0, 1),
               b0 = random_point(rng, 0, 1), b1 = random_point(rng, 0, 1);
    const double d = segment_segment_distance<0>(a0, a1, b0, b1, {false, false, false, false});
    const SegmentSegmentClosest c = segment_segment_closest(a0, a1, b0, b1);
    EXPECT_NEAR(d, ((a0 + c.s * (a1 - a0)) - (b0 + c.t * (b1 - b0))).norm(), 1e-12);
    double sampled = 1e9;
    const int n = 200;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j)
        sampled = std::min(sampled, ((a0 + (a1 - a0) * i / n) - (b0 + (b1 - b0) * j / n)).norm());
    EXPECT_LE(d, sampled + 1e-12);
    EXPECT_GE(d, sampled - 0.01 * ((a1 - a0).norm() + (b1 - b0).norm()));
  }
}

TEST(SegmentSegmentDistance, ParallelSegmentsMeasureBetweenTheirEnds) {
  const Vec3 a0(0, 0, 0), a1(1, 0, 0), b0(0.5, 0.3, 0), b1(2, 0.3, 0);
  EXPECT_NEAR(segment_segment_distance<0>(a0, a1, b0, b1, {false, false, false, false}), 0.3,
              1e-15);
  Eigen::Matrix<double, 6, 1> g;
  segment_segment_distance<6>(a0, a1, b0, b1, {true, true, false, false}, &g);
  EXPECT_TRUE(g.allFinite());
  EXPECT_NEAR(g.head<3>().norm() + g.tail<3>().norm(), 1.0, 1e-12);  // one end, unit gradient
}

TEST(SegmentSegmentDistance, DerivativesAreExactInEveryRegion) {
  std::mt19937 rng(4);
  // EE, PE with the end on a, PE with the end on b, PP.
  std::map<int, int> checked;
  for (int trial = 0, done = 0; trial < 20000 && done < 4 * kPerRegion; ++trial) {
    const std::array<Vec3, 4> P{random_point(rng, 0, 1), random_point(rng, 0, 1),
                                random_point(rng, 0, 1), random_point(rng, 0, 1)};
    const SegmentSegmentClosest c = segment_segment_closest(P[0], P[1], P[2], P[3]);
    const int region = (c.s_inside ? 0 : 1) + (c.t_inside ? 0 : 2);
    if (checked[region] >= kPerRegion) continue;
    if (segment_segment_distance<0>(P[0], P[1], P[2], P[3], {false, false, false, false}) < 0.05)
      continue;
    ++checked[region];
    ++done;
    const std::string what = "region " + std::to_string(region);
    const auto distance = [](const std::array<bool, 4>& varies) {
      return [varies](const std::array<Vec3, 4>& Q, auto* g, auto* h) {
        constexpr int N = std::remove_pointer_t<decltype(g)>::RowsAtCompileTime;
        return segment_segment_distance<N>(Q[0], Q[1], Q[2], Q[3], varies, g, h);
      };
    };
    const std::array<bool, 4> edge{true, true, false, false}, all{true, true, true, true};
    expect_exact_derivatives<6>(distance(edge), P, edge, what + " (one segment varies)");
    expect_exact_derivatives<12>(distance(all), P, all, what + " (both vary)");
  }
  for (int region = 0; region < 4; ++region)
    EXPECT_EQ(checked[region], kPerRegion) << "region " << region;
}

TEST(PointSegmentDistance, DerivativesAreExactInEveryRegion) {
  std::mt19937 rng(5);
  std::map<PointSegmentRegion, int> checked;
  for (int trial = 0, done = 0; trial < 20000 && done < 3 * kPerRegion; ++trial) {
    const std::array<Vec3, 3> P{random_point(rng, -1, 2), random_point(rng, 0, 1),
                                random_point(rng, 0, 1)};
    double t = 0;
    const PointSegmentRegion region = point_segment_region(P[0], P[1], P[2], &t);
    const double d = point_segment_distance<0>(P[0], P[1], P[2], {false, false, false});
    EXPECT_NEAR(d, (P[0] - (P[1] + t * (P[2] - P[1]))).norm(), 1e-12);
    if (checked[region] >= kPerRegion || d < 0.05) continue;
    ++checked[region];
    ++done;
    const std::string what = "region " + std::to_string(static_cast<int>(region));
    const auto distance = [](const std::array<bool, 3>& varies) {
      return [varies](const std::array<Vec3, 3>& Q, auto* g, auto* h) {
        constexpr int N = std::remove_pointer_t<decltype(g)>::RowsAtCompileTime;
        return point_segment_distance<N>(Q[0], Q[1], Q[2], varies, g, h);
      };
    };
    const std::array<bool, 3> point{true, false, false}, all{true, true, true};
    expect_exact_derivatives<3>(distance(point), P, point, what + " (point varies)");
    expect_exact_derivatives<9>(distance(all), P, all, what + " (all vary)");
  }
  for (auto region : {PointSegmentRegion::A, PointSegmentRegion::B, PointSegmentRegion::Interior})
    EXPECT_EQ(checked[region], kPerRegion) << "region " << static_cast<int>(region);
}

TEST(PointPointDistance, DerivativesAreExact) {
  std::mt19937 rng(6);
  for (int trial = 0; trial < kPerRegion; ++trial) {
    const std::array<Vec3, 2> P{random_point(rng, 0, 1), random_point(rng, 0, 1)};
    const auto distance = [](const std::array<Vec3, 2>& Q, auto* g, auto* h) {
      constexpr int N = std::remove_pointer_t<decltype(g)>::RowsAtCompileTime;
      return point_point_distance<N>(Q[0], Q[1], {true, N == 6}, g, h);
    };
    EXPECT_NEAR(distance(P, static_cast<Vec3*>(nullptr), static_cast<Mat3*>(nullptr)),
                (P[0] - P[1]).norm(), 1e-15);
    expect_exact_derivatives<3>(distance, P, {true, false}, "point");
    expect_exact_derivatives<6>(distance, P, {true, true}, "both");
  }
}

TEST(Barrier, IsZeroBeyondDhatInfiniteAtContactAndItsDerivativesAreExact) {
  const double dhat = 1e-3;
  EXPECT_EQ(barrier(dhat, dhat).value, 0);
  EXPECT_EQ(barrier(2 * dhat, dhat).first, 0);
  EXPECT_EQ(barrier(0, dhat).value, std::numeric_limits<double>::infinity());
  EXPECT_EQ(barrier(-1e-4, dhat).value, std::numeric_limits<double>::infinity());
  // C² at d̂: value, slope and curvature all go to zero from below.
  const BarrierValue near = barrier(dhat * (1 - 1e-6), dhat);
  EXPECT_LT(std::abs(near.value), 1e-15);
  EXPECT_LT(std::abs(near.first), 1e-12);
  EXPECT_LT(std::abs(near.second), 1e-5);
  for (double d : {1e-5, 1e-4, 3e-4, 7e-4, 9.9e-4}) {
    const double h = 1e-6 * d;
    const BarrierValue b = barrier(d, dhat);
    EXPECT_GT(b.value, 0);
    EXPECT_LT(b.first, 0);
    EXPECT_GT(b.second, 0);
    EXPECT_NEAR(b.first, (barrier(d + h, dhat).value - barrier(d - h, dhat).value) / (2 * h),
                1e-5 * std::abs(b.first));
    EXPECT_NEAR(b.second, (barrier(d + h, dhat).first - barrier(d - h, dhat).first) / (2 * h),
                1e-5 * std::abs(b.second));
  }
}

}  // namespace
}  // namespace shapectl
