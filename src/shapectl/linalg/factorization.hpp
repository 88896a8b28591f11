#pragma once
// One sparse Cholesky back-end behind SparseCholesky (sparse_cholesky.hpp): Eigen's simplicial
// LDLᵀ, the band (band_cholesky.hpp), our supernodal LLᵀ on CHOLMOD's analysis
// (permuted_cholmod.hpp) or CHOLMOD itself (cholmod_library.hpp). Every matrix is the lower
// triangle, compressed, of a symmetric matrix.
#include <shapectl/types.hpp>

namespace shapectl {

class Factorization {
 public:
  virtual ~Factorization() = default;
  // Symbolic analysis, once per pattern. `nodes`: the node pattern of `lower`
  // (node_pattern.hpp) if the caller has it, else null.
  virtual void analyze(const SparseMatrix& lower, const SparseMatrix* nodes) = 0;
  // Numeric factorization of a matrix of the analysed pattern; false unless it is (numerically)
  // positive definite and finite, and the factor is then unusable.
  virtual bool factorize(const SparseMatrix& lower) = 0;
  // Solves with the last successful factorization: one right-hand side, or several.
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const = 0;
  virtual Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const = 0;
  // A solve good enough to precondition with; exact unless a back-end has a cheaper one.
  virtual Eigen::VectorXd solve_preconditioner(const Eigen::VectorXd& rhs) const {
    return solve(rhs);
  }
  // Whether a solve costs a small fraction of a factorization (SparseCholesky::cheap_to_solve).
  virtual bool cheap_to_solve() const { return true; }
};

}  // namespace shapectl
