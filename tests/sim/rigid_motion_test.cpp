#include <shapectl/sim/rigid_motion.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include <shapectl/mesh/box_mesh.hpp>

namespace shapectl {
namespace {

Positions box_nodes() {
  const TetMesh mesh = make_box_mesh({0.32, 0.03, 0.03}, {8, 2, 2});
  Positions x(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i)
    x.segment<3>(3 * i) = mesh.rest_positions()[i] + Vec3(0.4, 0.1, 0.25);
  return x;
}

Positions moved_rigidly(const Positions& x, const Mat3& R, const Vec3& t) {
  Positions out(x.size());
  for (int i = 0; i < x.size() / 3; ++i) out.segment<3>(3 * i) = R * x.segment<3>(3 * i) + t;
  return out;
}

TEST(RigidMotion, BestFitRotationRecoversATurnOfScatteredPoints) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Positions from(3 * 40);
  for (int k = 0; k < from.size(); ++k) from[k] = u(rng);
  const Mat3 R = Eigen::AngleAxisd(2.1, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  const Mat3 found = best_fit_rotation(from, moved_rigidly(from, R, Vec3(3, -1, 2)));
  EXPECT_LT((found - R).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(found.determinant(), 1.0, 1e-12);
}

TEST(RigidMotion, BestFitRotationOfMirroredPointsIsAProperRotation) {
  const Positions from = box_nodes();
  Positions mirrored = from;
  for (int i = 0; i < from.size() / 3; ++i) mirrored[3 * i + 1] *= -1;
  EXPECT_NEAR(best_fit_rotation(from, mirrored).determinant(), 1.0, 1e-12);
}

TEST(RigidMotion, RotateNodesTurnsEveryNodeAndTheTransposeTurnsBack) {
  const Positions x = box_nodes();
  const Mat3 R = Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix();
  const Eigen::VectorXd turned = rotate_nodes(R, x);
  EXPECT_LT((turned - moved_rigidly(x, R, Vec3::Zero())).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((rotate_nodes(R, turned, /*transpose=*/true) - x).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(RigidMotion, AnInfinitesimalRotationBecomesTheFiniteOne) {
  // u = v + ω × (x − c): the linear prediction of a turn by |ω| = 0.3 rad, which stretches the
  // bar by 1 − cos-like terms; made finite it is the exact turn and keeps every distance.
  const Positions x = box_nodes();
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < x.size() / 3; ++i) c += x.segment<3>(3 * i);
  c /= x.size() / 3;
  const Vec3 omega(0.1, -0.2, 0.2), v(0.01, 0.02, -0.03);
  Eigen::VectorXd u(x.size());
  for (int i = 0; i < x.size() / 3; ++i)
    u.segment<3>(3 * i) = v + omega.cross(x.segment<3>(3 * i) - c);
  const Mat3 R = Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix();
  const Positions expected = moved_rigidly(x, R, c + v - R * c);
  const Positions got = with_finite_rotation(x, u);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-12);
  const double far_apart = (x.head<3>() - x.tail<3>()).norm();
  EXPECT_NEAR((got.head<3>() - got.tail<3>()).norm(), far_apart, 1e-12);
  EXPECT_GT(((x + u).head<3>() - (x + u).tail<3>()).norm() - far_apart, 1e-3);  // linear stretches
}

TEST(RigidMotion, AMotionWithoutRotationIsLeftAlone) {
  // A translation plus a stretch along the axes: no angular momentum about the centroid of a
  // symmetric box, so nothing to make finite.
  const Positions x = box_nodes();
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < x.size() / 3; ++i) c += x.segment<3>(3 * i);
  c /= x.size() / 3;
  Eigen::VectorXd u(x.size());
  for (int i = 0; i < x.size() / 3; ++i)
    u.segment<3>(3 * i) =
        Vec3(0.01, 0, -0.02) + Vec3(0.1, -0.05, 0.02).cwiseProduct(x.segment<3>(3 * i) - c);
  EXPECT_LT((with_finite_rotation(x, u) - (x + u)).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace shapectl
