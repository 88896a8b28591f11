#include <shapectl/robot/kinematics.hpp>

#include <cassert>
#include <cmath>

namespace shapectl {

namespace {

// R ← R · Rot(axis, angle) for a unit axis, by Rodrigues' formula.
void rotate_about(Mat3& R, const Vec3& axis, double angle) {
  const double s = std::sin(angle);
  const double c = std::cos(angle);
  // Unit axes are the common case (all YuMi joints turn about z): two columns change.
  if (axis.x() == 0 && axis.y() == 0) {
    const double sz = axis.z() > 0 ? s : -s;
    const Vec3 c0 = R.col(0);
    R.col(0) = c * c0 + sz * R.col(1);
    R.col(1) = c * R.col(1) - sz * c0;
    return;
  }
  Mat3 K;
  K << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  R = R * (Mat3::Identity() + s * K + (1 - c) * (K * K));
}

}  // namespace

void forward_kinematics(const RobotModel& model, const Eigen::VectorXd& active,
                        KinematicsState& state) {
  assert(active.size() == model.active_count());
  const auto links = static_cast<std::size_t>(model.link_count());
  const auto joints = static_cast<std::size_t>(model.joint_count());
  state.T_world_link.resize(links);
  state.joint_axes_world.resize(joints);
  state.joint_origins_world.resize(joints);
  state.joints.resize(model.joint_count());
  // Joint values: active from θ, others fixed; mimic joints after their (non-mimic) masters.
  const auto& all = model.joints();
  for (std::size_t j = 0; j < joints; ++j) {
    const int a = model.active_index(static_cast<int>(j));
    state.joints[static_cast<long>(j)] =
        a >= 0 ? active[a] : model.fixed_value(static_cast<int>(j));
  }
  for (std::size_t j = 0; j < joints; ++j)
    if (all[j].mimic_master >= 0)
      state.joints[static_cast<long>(j)] =
          all[j].mimic_multiplier * state.joints[all[j].mimic_master] + all[j].mimic_offset;

  state.T_world_link[0].setIdentity();
  for (std::size_t j = 0; j < joints; ++j) {
    const Joint& joint = all[j];
    const Eigen::Isometry3d& T_parent =
        state.T_world_link[static_cast<std::size_t>(joint.parent_link)];
    Eigen::Isometry3d& T = state.T_world_link[static_cast<std::size_t>(joint.child_link)];
    T.linear().noalias() = T_parent.linear() * joint.T_parent_child.linear();
    T.translation().noalias() = T_parent.linear() * joint.T_parent_child.translation();
    T.translation() += T_parent.translation();
    if (!joint.movable()) continue;
    const double q = state.joints[static_cast<long>(j)];
    const Vec3 axis_world = T.linear() * joint.axis;
    state.joint_axes_world[j] = axis_world;
    state.joint_origins_world[j] = T.translation();
    if (joint.type == JointType::Prismatic) {
      T.translation() += q * axis_world;
    } else {
      Mat3 R = T.linear();
      rotate_about(R, joint.axis, q);
      T.linear() = R;
    }
  }
}

KinematicsState forward_kinematics(const RobotModel& model, const Eigen::VectorXd& active) {
  KinematicsState state;
  forward_kinematics(model, active, state);
  return state;
}

void point_jacobian_world(const RobotModel& model, const KinematicsState& state, int link,
                          const Vec3& point_world, Eigen::Ref<Eigen::Matrix3Xd> jacobian) {
  assert(jacobian.cols() == model.active_count());
  jacobian.setZero();
  for (const auto& e : model.jacobian_entries(link)) {
    const auto j = static_cast<std::size_t>(e.joint);
    const Vec3& axis = state.joint_axes_world[j];
    if (model.joints()[j].type == JointType::Prismatic) {
      jacobian.col(e.column) += e.scale * axis;
    } else {
      jacobian.col(e.column) += e.scale * axis.cross(point_world - state.joint_origins_world[j]);
    }
  }
}

Eigen::Matrix3Xd point_jacobian(const RobotModel& model, const KinematicsState& state, int link,
                                const Vec3& point_link) {
  Eigen::Matrix3Xd jacobian(3, model.active_count());
  point_jacobian_world(model, state, link,
                       state.T_world_link[static_cast<std::size_t>(link)] * point_link, jacobian);
  return jacobian;
}

void add_point_jacobian_transpose(const RobotModel& model, const KinematicsState& state, int link,
                                  const Vec3& point_world, const Vec3& force,
                                  Eigen::Ref<Eigen::VectorXd> gradient) {
  for (const auto& e : model.jacobian_entries(link)) {
    const auto j = static_cast<std::size_t>(e.joint);
    const Vec3& axis = state.joint_axes_world[j];
    // a·((p − o) × f) = ((p − o) × f)·a: the torque of f about the joint axis.
    const double along = model.joints()[j].type == JointType::Prismatic
                             ? axis.dot(force)
                             : axis.dot((point_world - state.joint_origins_world[j]).cross(force));
    gradient[e.column] += e.scale * along;
  }
}

}  // namespace shapectl
