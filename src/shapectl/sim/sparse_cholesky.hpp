#pragma once
// Sparse Cholesky with the symbolic analysis done once per pattern and reused.
// Simplicial LDLᵀ (Eigen) for small systems, supernodal LLᵀ (CHOLMOD + OpenBLAS) for large
// ones; the crossover comes from bench/statics_bench.cpp on a 2-core machine.
#include <memory>

#include <shapectl/types.hpp>

namespace shapectl {

class SparseCholesky {
 public:
  enum class Backend { SimplicialLDLT, CholmodSupernodal };
  // The faster backend for a system of this many unknowns.
  static Backend choose(int dof_count);

  explicit SparseCholesky(Backend backend);
  ~SparseCholesky();
  Backend backend() const { return backend_; }
  // Symbolic analysis; call again only when the pattern changes.
  void analyze(const SparseMatrix& lower);
  // Numeric factorization of the lower-triangle matrix. False if it is not (numerically)
  // positive definite; the factor is then unusable.
  bool factorize(const SparseMatrix& lower);
  // Solves with the last successful factorization.
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;

 private:
  struct Impl;
  Backend backend_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace shapectl
