#pragma once
// Sparse Cholesky with the symbolic analysis done once per pattern and reused. Four
// back-ends (factorization.hpp): simplicial LDLᵀ (Eigen), a dense band after reverse
// Cuthill–McKee (LAPACK; the fastest for bars, box frames and small blocks), supernodal LLᵀ
// (CHOLMOD's analysis, our kernels or, for large factorizations, CHOLMOD's: permuted_cholmod.hpp;
// for compact and unstructured meshes) and CHOLMOD on its own (cholmod_library.hpp, a reference,
// never chosen automatically). Chosen from the matrix unless fixed; the rule's numbers come from
// bench/statics_bench.cpp and docs/benchmarks.md.
#include <memory>
#include <optional>

#include <shapectl/linalg/cholesky_backend.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

class Factorization;

// The flops of Eigen's LDLᵀ (as Σ_j (|L_j| + 1)² over its columns, diagonal included) of a
// matrix in node blocks, estimated from its node pattern (node_pattern.hpp) ordered by AMD: a
// node column of length c stands for three dof columns of about 3c, so ~27x its flops.
double ldlt_flops_by_nodes(const SparseMatrix& nodes);

class SparseCholesky {
 public:
  using Backend = CholeskyBackend;

  // A fixed backend, or none: then analyze() picks one for the matrix.
  explicit SparseCholesky(std::optional<Backend> backend = std::nullopt);
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;
  // The backend in use (decided by the first analyze() when automatic).
  Backend backend() const { return backend_; }
  // Symbolic analysis; call again only when the pattern changes. `nodes`: the node pattern of
  // `lower` (node_pattern.hpp), if the caller has it (HessianAssembler does); else it is found.
  void analyze(const SparseMatrix& lower, const SparseMatrix* nodes = nullptr);
  // Numeric factorization of the lower-triangle matrix. False if it is not (numerically)
  // positive definite; the factor is then unusable.
  bool factorize(const SparseMatrix& lower);
  // Solves with the last successful factorization.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;
  // A solve good enough to precondition with: the band's factor in single precision
  // (BandCholesky::solve_single_precision); the other back-ends solve exactly.
  Eigen::VectorXd solve_preconditioner(const Eigen::VectorXd& rhs) const;
  // Whether a solve costs a small fraction of a factorization, so that conjugate gradients
  // preconditioned with the factor pay: the band's single-precision solve does; CHOLMOD's
  // solve does not (a 60x60x1 plate took 19 Newton iterations and 1.25 s with such steps,
  // 7 and 0.70 s without; docs/benchmarks.md, "the back-end choice, again").
  bool cheap_to_solve() const;

 private:
  // The automatic choice (sets backend_), analysed.
  std::unique_ptr<Factorization> choose(const SparseMatrix& lower, const SparseMatrix* nodes);
  bool automatic_;
  Backend backend_;
  std::unique_ptr<Factorization> factorization_;
};

}  // namespace shapectl
