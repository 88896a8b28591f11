#pragma once
// Vocabulary types shared by every area. SI units throughout.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

namespace shapectl {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Triplets = std::vector<Eigen::Triplet<double>>;
using SparseMatrix = Eigen::SparseMatrix<double>;
// Node positions stacked as [x0 y0 z0 x1 y1 z1 ...]; size 3n.
using Positions = Eigen::VectorXd;

}  // namespace shapectl
