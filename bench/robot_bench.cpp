// YuMi kinematics and collision barriers; orocos KDL doing the same work as the reference.
#include <benchmark/benchmark.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>

#include <cmath>
#include <cstdlib>
#include <iostream>

#include <shapectl/robot/collision_spheres.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace {

using namespace shapectl;

const std::string kYumiDir = SHAPECTL_SOURCE_DIR "/data/robots/yumi/";
const char* const kArmJoints[] = {"yumi_joint_1_r", "yumi_joint_2_r", "yumi_joint_7_r",
                                  "yumi_joint_3_r", "yumi_joint_4_r", "yumi_joint_5_r",
                                  "yumi_joint_6_r", "yumi_joint_1_l", "yumi_joint_2_l",
                                  "yumi_joint_7_l", "yumi_joint_3_l", "yumi_joint_4_l",
                                  "yumi_joint_5_l", "yumi_joint_6_l"};

RobotModel yumi_arms() {
  RobotModel model = RobotModel::load_urdf_file(kYumiDir + "yumi.urdf");
  model.set_active_joints(std::vector<std::string>(std::begin(kArmJoints), std::end(kArmJoints)));
  return model;
}

// A fixed, generic configuration (radians), 14 arm joints.
Eigen::VectorXd test_joints() {
  Eigen::VectorXd q(14);
  q << 0.3, -0.5, 0.4, 0.7, -0.4, 0.2, 0.6, -0.3, -0.5, -0.4, 0.7, 0.4, 0.2, -0.6;
  return q;
}

KDL::Frame to_kdl(const Eigen::Isometry3d& T) {
  const Mat3 R = T.linear();
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0),
                                  R(2, 1), R(2, 2)),
                    KDL::Vector(T.translation().x(), T.translation().y(), T.translation().z()));
}

// The chain root → `tip` as kdl_parser builds it: each joint rotates about its axis through
// its origin, both in the parent frame, then the fixed origin transform follows.
KDL::Chain kdl_chain(const RobotModel& model, const std::string& tip) {
  std::vector<int> joints;
  for (int j = model.links()[static_cast<std::size_t>(model.link_index(tip))].parent_joint; j >= 0;
       j = model
               .links()[static_cast<std::size_t>(
                   model.joints()[static_cast<std::size_t>(j)].parent_link)]
               .parent_joint)
    joints.insert(joints.begin(), j);
  KDL::Chain chain;
  for (const int j : joints) {
    const Joint& joint = model.joints()[static_cast<std::size_t>(j)];
    const KDL::Frame origin = to_kdl(joint.T_parent_child);
    const Vec3 axis = joint.T_parent_child.linear() * joint.axis;
    const KDL::Joint kdl_joint =
        joint.movable() ? KDL::Joint(joint.name, origin.p,
                                     KDL::Vector(axis.x(), axis.y(), axis.z()), KDL::Joint::RotAxis)
                        : KDL::Joint(joint.name, KDL::Joint::None);
    chain.addSegment(KDL::Segment(model.links()[static_cast<std::size_t>(joint.child_link)].name,
                                  kdl_joint, origin));
  }
  return chain;
}

struct KdlArm {
  explicit KdlArm(KDL::Chain c)
      : chain(std::move(c)),
        fk(chain),
        jac(chain),
        q(chain.getNrOfJoints()),
        jacobian(chain.getNrOfJoints()) {}
  KDL::Chain chain;
  KDL::ChainFkSolverPos_recursive fk;
  KDL::ChainJntToJacSolver jac;
  KDL::JntArray q;
  KDL::Frame tip;
  KDL::Jacobian jacobian;
};

// Both implementations must agree before their speed is compared.
void check_agreement(const RobotModel& model, KdlArm& right, KdlArm& left) {
  const Eigen::VectorXd q = test_joints();
  const KinematicsState state = forward_kinematics(model, q);
  for (int i = 0; i < 7; ++i) {
    right.q(static_cast<unsigned>(i)) = q[i];
    left.q(static_cast<unsigned>(i)) = q[7 + i];
  }
  const char* tips[] = {"gripper_r_tcp", "gripper_l_tcp"};
  KdlArm* arms[] = {&right, &left};
  for (int a = 0; a < 2; ++a) {
    arms[a]->fk.JntToCart(arms[a]->q, arms[a]->tip);
    arms[a]->jac.JntToJac(arms[a]->q, arms[a]->jacobian);
    const int link = model.link_index(tips[a]);
    const Vec3 p = state.T_world_link[static_cast<std::size_t>(link)].translation();
    const Eigen::Matrix3Xd J = point_jacobian(model, state, link, Vec3::Zero());
    double error = (p - Vec3(arms[a]->tip.p.x(), arms[a]->tip.p.y(), arms[a]->tip.p.z())).norm();
    for (int i = 0; i < 7; ++i)
      for (int r = 0; r < 3; ++r)
        error = std::max(error,
                         std::abs(J(r, 7 * a + i) - arms[a]->jacobian(static_cast<unsigned>(r),
                                                                      static_cast<unsigned>(i))));
    if (error > 1e-12) {
      std::cerr << "KDL and shapectl disagree on " << tips[a] << " by " << error << "\n";
      std::abort();
    }
  }
}

void BM_YumiForwardKinematicsAndToolJacobians(benchmark::State& bench) {
  const RobotModel model = yumi_arms();
  const int right = model.link_index("gripper_r_tcp");
  const int left = model.link_index("gripper_l_tcp");
  Eigen::VectorXd q = test_joints();
  KinematicsState state = forward_kinematics(model, q);
  Eigen::Matrix3Xd jacobian_right(3, 14), jacobian_left(3, 14);
  for (auto _ : bench) {
    q[0] += 1e-9;  // a new configuration each time
    forward_kinematics(model, q, state);
    point_jacobian_world(model, state, right,
                         state.T_world_link[static_cast<std::size_t>(right)].translation(),
                         jacobian_right);
    point_jacobian_world(model, state, left,
                         state.T_world_link[static_cast<std::size_t>(left)].translation(),
                         jacobian_left);
    benchmark::DoNotOptimize(jacobian_right.data());
    benchmark::DoNotOptimize(jacobian_left.data());
  }
}
BENCHMARK(BM_YumiForwardKinematicsAndToolJacobians);

void BM_KdlForwardKinematicsAndToolJacobians(benchmark::State& bench) {
  const RobotModel model = yumi_arms();
  KdlArm right(kdl_chain(model, "gripper_r_tcp"));
  KdlArm left(kdl_chain(model, "gripper_l_tcp"));
  check_agreement(model, right, left);
  for (auto _ : bench) {
    right.q(0) += 1e-9;
    for (KdlArm* arm : {&right, &left}) {
      arm->fk.JntToCart(arm->q, arm->tip);
      arm->jac.JntToJac(arm->q, arm->jacobian);
      benchmark::DoNotOptimize(arm->jacobian.data.data());
    }
  }
}
BENCHMARK(BM_KdlForwardKinematicsAndToolJacobians);

// Every checked sphere pair's barrier with its gradient over the 14 arm joints.
void collision_barrier(benchmark::State& bench, const Eigen::VectorXd& q) {
  const RobotModel model = yumi_arms();
  const CollisionModel spheres =
      CollisionModel::load_json_file(model, kYumiDir + "yumi_spheres.json");
  const KinematicsState state = forward_kinematics(model, q);
  Eigen::VectorXd gradient(14);
  for (auto _ : bench) {
    benchmark::DoNotOptimize(spheres.value(model, state, &gradient));
    benchmark::DoNotOptimize(gradient.data());
  }
  bench.counters["pairs"] = spheres.pair_count();
  bench.counters["barrier"] = spheres.value(model, state);
}

void BM_YumiCollisionBarrierAtHome(benchmark::State& bench) {
  Eigen::VectorXd q(14);
  const double d = M_PI / 180;
  q << 0, -25 * d, -50 * d, 45 * d, 70 * d, -25 * d, 0, 0, -25 * d, 50 * d, 45 * d, -70 * d,
      -25 * d, 0;
  collision_barrier(bench, q);
}
BENCHMARK(BM_YumiCollisionBarrierAtHome);

void BM_YumiCollisionBarrierColliding(benchmark::State& bench) {
  collision_barrier(bench, test_joints());
}
BENCHMARK(BM_YumiCollisionBarrierColliding);

}  // namespace

BENCHMARK_MAIN();
