#include <shapectl/sim/rigid_motion.hpp>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace shapectl {

namespace {
int nodes_of(const Eigen::VectorXd& v) { return static_cast<int>(v.size() / 3); }

Vec3 centroid(const Eigen::VectorXd& v) {
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < nodes_of(v); ++i) c += v.segment<3>(3 * i);
  return c / std::max(1, nodes_of(v));
}
}  // namespace

Mat3 best_fit_rotation(const Positions& from, const Positions& to) {
  const Vec3 c_from = centroid(from), c_to = centroid(to);
  Mat3 covariance = Mat3::Zero();
  for (int i = 0; i < nodes_of(from); ++i)
    covariance += (to.segment<3>(3 * i) - c_to) * (from.segment<3>(3 * i) - c_from).transpose();
  const Eigen::JacobiSVD<Mat3> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 reflection = Mat3::Identity();  // a proper rotation, never a mirror
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) reflection(2, 2) = -1;
  return svd.matrixU() * reflection * svd.matrixV().transpose();
}

Eigen::VectorXd rotate_nodes(const Mat3& R, const Eigen::VectorXd& v, bool transpose) {
  const Mat3 turn = transpose ? Mat3(R.transpose()) : R;
  Eigen::VectorXd out(v.size());
  for (int i = 0; i < nodes_of(v); ++i) out.segment<3>(3 * i) = turn * v.segment<3>(3 * i);
  return out;
}

Positions with_finite_rotation(const Positions& x, const Eigen::VectorXd& u) {
  const Vec3 c = centroid(x), v = centroid(u);
  // Least squares for ω: the nodes' inertia tensor times ω = their angular momentum.
  Mat3 inertia = Mat3::Zero();
  Vec3 momentum = Vec3::Zero();
  for (int i = 0; i < nodes_of(x); ++i) {
    const Vec3 r = x.segment<3>(3 * i) - c;
    inertia += r.squaredNorm() * Mat3::Identity() - r * r.transpose();
    momentum += r.cross(u.segment<3>(3 * i) - v);
  }
  const Vec3 omega = inertia.fullPivLu().solve(momentum);
  const double angle = omega.norm();
  if (!(angle > 0) || !omega.allFinite()) return x + u;
  const Mat3 R = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  Positions out(x.size());
  for (int i = 0; i < nodes_of(x); ++i) {
    const Vec3 r = x.segment<3>(3 * i) - c;
    const Vec3 deformation = u.segment<3>(3 * i) - v - omega.cross(r);
    out.segment<3>(3 * i) = c + v + R * (r + deformation);
  }
  return out;
}

}  // namespace shapectl
