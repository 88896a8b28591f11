#include <shapectl/sim/contact_force_jacobian.hpp>

namespace shapectl {

Eigen::MatrixXd contact_force_jacobian(const ObstacleContact& contact, const RobotModel& robot,
                                       const KinematicsState& state, const Positions& x) {
  Eigen::MatrixXd dF = Eigen::MatrixXd::Zero(x.size(), robot.active_count());
  Eigen::Matrix3Xd J(3, robot.active_count());
  contact.for_each_coupling(x, [&](int node, int obstacle, const Vec3& p, const Mat3& B) {
    point_jacobian_world(robot, state, contact.obstacles()[obstacle].link, p, J);
    dF.middleRows<3>(3 * node) -= B * J;
  });
  return dF;
}

void add_contact_force_jacobian_transpose_times(const ObstacleContact& contact,
                                                const RobotModel& robot,
                                                const KinematicsState& state, const Positions& x,
                                                const Eigen::VectorXd& lambda,
                                                Eigen::VectorXd& out) {
  contact.for_each_coupling(x, [&](int node, int obstacle, const Vec3& p, const Mat3& B) {
    add_point_jacobian_transpose(robot, state, contact.obstacles()[obstacle].link, p,
                                 -B.transpose() * lambda.segment<3>(3 * node), out);
  });
}

}  // namespace shapectl
