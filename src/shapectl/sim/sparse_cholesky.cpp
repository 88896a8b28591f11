#include <shapectl/sim/sparse_cholesky.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>

namespace shapectl {

struct SparseCholesky::Impl {
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> ldlt;
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> cholmod;
};

SparseCholesky::Backend SparseCholesky::choose(int dof_count) {
  // Measured crossover (bench/statics_bench.cpp BM_Backend*, README): LDLT is as fast or faster
  // up to ~1.5k tets (1,275 unknowns); CHOLMOD is 2x faster at 5k tets and 6x at 24k.
  return dof_count < 2500 ? Backend::SimplicialLDLT : Backend::CholmodSupernodal;
}

SparseCholesky::SparseCholesky(Backend backend) : backend_(backend), impl_(std::make_unique<Impl>()) {
  // Not positive definite is an expected outcome (we fall back), not something to print.
  impl_->cholmod.cholmod().print = 0;
}

SparseCholesky::~SparseCholesky() = default;

void SparseCholesky::analyze(const SparseMatrix& lower) {
  if (backend_ == Backend::SimplicialLDLT)
    impl_->ldlt.analyzePattern(lower);
  else
    impl_->cholmod.analyzePattern(lower);
}

bool SparseCholesky::factorize(const SparseMatrix& lower) {
  if (backend_ == Backend::CholmodSupernodal) {
    impl_->cholmod.factorize(lower);
    return impl_->cholmod.info() == Eigen::Success;
  }
  impl_->ldlt.factorize(lower);
  if (impl_->ldlt.info() != Eigen::Success) return false;
  // LDLᵀ also "succeeds" on indefinite matrices: positive definite means every pivot > 0,
  // and a pivot tiny next to the largest means the matrix is singular in double precision.
  const auto& D = impl_->ldlt.vectorD();
  return D.minCoeff() > 1e-13 * D.cwiseAbs().maxCoeff();
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& rhs) const {
  if (backend_ == Backend::SimplicialLDLT) return impl_->ldlt.solve(rhs);
  return impl_->cholmod.solve(rhs);
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& rhs) const {
  if (backend_ == Backend::SimplicialLDLT) return impl_->ldlt.solve(rhs);
  return impl_->cholmod.solve(rhs);
}

}  // namespace shapectl
