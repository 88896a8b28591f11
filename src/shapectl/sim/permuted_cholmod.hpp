#pragma once
// CHOLMOD's supernodal LLᵀ of P A Pᵀ, with the fill-reducing order P applied by us: the
// matrix is gathered into that order through a slot per entry (found once), and CHOLMOD
// analyses and factors it in its natural order. Given an order of its own, CHOLMOD transposes
// the matrix twice through the permutation at every factorization and permutes every solve:
// a TetGen frame's factorization took 5.0 ms that way and 3.6 ms this way (docs/benchmarks.md,
// "session 7").
#include <memory>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

class PermutedCholmod {
 public:
  PermutedCholmod();
  ~PermutedCholmod();
  PermutedCholmod(PermutedCholmod&&) noexcept;
  PermutedCholmod& operator=(PermutedCholmod&&) noexcept;

  // Symbolic analysis of `lower` (lower triangle, compressed) in `order`: order[k] is the row
  // and column that comes k-th, and `order_flops` the factorization's flops in it (an estimate
  // will do). An empty order: CHOLMOD's own choice (AMD, or METIS where AMD's factor is dense),
  // then its postorder, with its own flop count.
  void analyze(const SparseMatrix& lower, std::vector<int> order = {}, double order_flops = 0);
  // The factorization's flops, from the analysis.
  double flops() const { return flops_; }
  // Numeric factorization of a matrix with the analysed pattern. False if it is not (numerically)
  // positive definite; the factor is then unusable.
  bool factorize(const SparseMatrix& lower);
  // Solves with the last successful factorization. Threads may solve at once.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double flops_ = 0;
};

}  // namespace shapectl
