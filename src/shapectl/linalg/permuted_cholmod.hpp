#pragma once
// The supernodal LLᵀ of P A Pᵀ, with the fill-reducing order P applied by us: the matrix is
// gathered into that order through a slot per entry (found once), and our kernels factor it
// and solve with it (supernodal_llt.hpp; CHOLMOD's own for large factorizations). Given an
// order of its own, CHOLMOD transposes the matrix twice through the permutation at every
// factorization and permutes every solve: a TetGen frame's factorization took 5.0 ms that way
// and 3.6 ms this way (docs/benchmarks.md, "session 7").
//
// A FEM Hessian is analysed on its node pattern (analyze_nodes): the order, the flops and the
// factor's structure come from CHOLMOD's analysis of the nodes, a ninth of the entries, and the
// matrix is gathered in whole 3×3 node blocks (the rows and columns of held dofs as zeros).
// CHOLMOD analyses the dofs only where its kernels factor.
#include <memory>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

class PermutedCholmod {
 public:
  // Our own kernels factor (supernodal_llt.hpp) below this many flops, where they beat
  // CHOLMOD on one thread (TetGen frame 2.1x, 14-cell cube 1.1x). Above it CHOLMOD
  // factors, its BLAS calls on all cores (a 20-cell cube, 1.1e10 flops: 208 ms on 2 threads,
  // ours 323 ms).
  static constexpr double kOwnKernelsBelowFlops = 3e9;
  explicit PermutedCholmod(double own_kernels_below_flops = kOwnKernelsBelowFlops);
  ~PermutedCholmod();
  PermutedCholmod(PermutedCholmod&&) noexcept;
  PermutedCholmod& operator=(PermutedCholmod&&) noexcept;

  // Symbolic analysis of `lower` (lower triangle, compressed) in `order`: order[k] is the row
  // and column that comes k-th. An empty order: CHOLMOD's own choice (AMD, or METIS where AMD's
  // factor is dense), then its postorder.
  void analyze(const SparseMatrix& lower, std::vector<int> order = {});
  // Symbolic analysis of `lower`, a matrix of 3n rows in node blocks, with its node pattern
  // `nodes` (node_pattern.hpp): CHOLMOD's choice of order for the nodes, by its own rule, then
  // its postorder; each node's three dofs come together.
  void analyze_nodes(const SparseMatrix& lower, const SparseMatrix& nodes);
  // The factorization's flops, from the analysis.
  double flops() const { return flops_; }
  // Whether our own kernels factor, from the analysis's flops.
  bool own_kernels() const { return flops_ < own_kernels_below_flops_; }
  // Numeric factorization of a matrix with the analysed pattern. False if it is not (numerically)
  // positive definite or has a non-finite entry; the factor is then unusable.
  bool factorize(const SparseMatrix& lower);
  // Solves with the last factorization, which must have succeeded. Threads may solve at once.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;

 private:
  struct Impl;
  // The teams (for our factorization and every solve); CHOLMOD's factor freed for our kernels.
  void finish_analysis();
  std::unique_ptr<Impl> impl_;
  double flops_ = 0;
  double own_kernels_below_flops_;
};

}  // namespace shapectl
