#pragma once
// The "cholmod-library" back-end: CHOLMOD as its authors ship it — cholmod_analyze,
// cholmod_factorize and cholmod_solve on the matrix as given, with CHOLMOD's default ordering
// and its own choice of supernodal or simplicial factor. None of our kernels run (the count of
// own_kernel_calls.hpp stays put): a reference to check ours against, never chosen
// automatically. Its BLAS's threads are the caller's to set (SparseCholesky sets them as for
// "cholmod").
#include <memory>

#include <shapectl/linalg/factorization.hpp>

namespace shapectl {

class CholmodLibrary : public Factorization {
 public:
  CholmodLibrary();
  ~CholmodLibrary() override;
  CholmodLibrary(const CholmodLibrary&) = delete;
  CholmodLibrary& operator=(const CholmodLibrary&) = delete;

  // CHOLMOD analyses the dof matrix itself; `nodes` is not used.
  void analyze(const SparseMatrix& lower, const SparseMatrix* nodes) override;
  bool factorize(const SparseMatrix& lower) override;
  // Threads may solve at once: they take turns (a solve writes CHOLMOD's common workspace).
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const override;
  // CHOLMOD's solve is no small fraction of its factorization.
  bool cheap_to_solve() const override { return false; }
  // The factorization's flops, from the analysis.
  double flops() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace shapectl
