#include <shapectl/sim/sparse_cholesky.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <amd.h>
#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <tbb/parallel_invoke.h>
#include <vector>

#include <shapectl/runtime/blas_threads.hpp>
#include <shapectl/sim/band_cholesky.hpp>
#include <shapectl/sim/node_pattern.hpp>
#include <shapectl/sim/permuted_cholmod.hpp>
#include <shapectl/sim/serial_openmp.hpp>

namespace shapectl {

using runtime::use_blas_threads;  // one thread, or one per core (runtime/blas_threads.hpp)

namespace {
// Eigen's LDLᵀ, plus the flop count of its factorization from the symbolic analysis.
struct CountingLdlt : Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> {
  double flops() const {
    double f = 0;
    for (int j = 0; j < m_nonZerosPerCol.size(); ++j)
      f += double(m_nonZerosPerCol[j] + 1) * (m_nonZerosPerCol[j] + 1);
    return f;
  }
};

// CHOLMOD's analysis, on the node pattern where `lower` has one (`nodes`, or found here):
// analysing the dofs orders a nine times larger graph (7 of 12 ms on a 12.8k-tet TetGen bar).
void analyze_sparse(PermutedCholmod& cholmod, const SparseMatrix& lower,
                    const SparseMatrix* nodes) {
  SerialOpenMp serial;
  std::optional<SparseMatrix> found;
  if (!nodes && (found = node_pattern(lower))) nodes = &*found;
  if (nodes) cholmod.analyze_nodes(lower, *nodes);
  else cholmod.analyze(lower);
}
}  // namespace

// SuiteSparse's AMD orders the nodes and counts the multiply-subtract pairs Σ c(c+1)/2 of that
// order, c a column's entries below the diagonal, in one pass, where Eigen's ordering and
// symbolic analysis took 0.15 ms more of a 960-tet box frame's 1.8 ms solve (paired).
// Σ (c+1)² = 2 Σ c(c+1)/2 + Σ c + n.
double ldlt_flops_by_nodes(const SparseMatrix& nodes) {
  if (!nodes.isCompressed()) {
    SparseMatrix compressed = nodes;
    compressed.makeCompressed();
    return ldlt_flops_by_nodes(compressed);
  }
  const int n = static_cast<int>(nodes.rows());
  std::vector<int> order(n);
  double info[AMD_INFO];
  if (amd_order(n, nodes.outerIndexPtr(), nodes.innerIndexPtr(), order.data(), nullptr, info) < 0)
    throw std::runtime_error("AMD could not order the node pattern");
  return 27 * (2 * info[AMD_NMULTSUBS_LDL] + info[AMD_LNZ] + n);
}

struct SparseCholesky::Impl {
  CountingLdlt ldlt;
  BandCholesky band;
  PermutedCholmod cholmod;
  bool cholmod_blas_threads = false;  // see factorize()
  bool cholmod_analysed = false;      // by choose(): analyze() need not analyse again
};

SparseCholesky::SparseCholesky(std::optional<Backend> backend)
    : automatic_(!backend),
      backend_(backend.value_or(Backend::SimplicialLDLT)),
      impl_(std::make_unique<Impl>()) {}

SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze(const SparseMatrix& lower, const SparseMatrix* nodes) {
  impl_->cholmod_analysed = false;
  if (automatic_) backend_ = choose(lower, nodes);
  switch (backend_) {
    case Backend::SimplicialLDLT: impl_->ldlt.analyzePattern(lower); break;
    case Backend::Band:
      if (!automatic_) impl_->band.analyze(lower);  // choose() did
      break;
    case Backend::CholmodSupernodal:
      if (!impl_->cholmod_analysed) analyze_sparse(impl_->cholmod, lower, nodes);
      impl_->cholmod_blas_threads = !impl_->cholmod.own_kernels();
      break;
  }
}

SparseCholesky::Backend SparseCholesky::choose(const SparseMatrix& lower,
                                               const SparseMatrix* nodes) {
  // The band Cholesky after reverse Cuthill–McKee runs at several times the flop rate of the
  // sparse ones (dense kernels), so it is the faster while it does at most a few times their
  // flops. Measured on 2 cores with CHOLMOD on one thread (docs/benchmarks.md, "the back-end
  // choice, again"): against CHOLMOD the band wins clearly below 2x (box bars of 12k and 50k
  // tets at 0.8-1.3x solve 1.7-1.9x faster as a band), the two are even within 5 % from 2.9x
  // to 5.5x (box cubes of 14 and 20 cells, a TetGen bar) and CHOLMOD takes far less memory;
  // against Eigen's simplicial LDLᵀ, used below 2,500 unknowns, the crossover is near 8x.
  // Over 1 GiB of band, always the sparse one.
  constexpr double kCholmodAllowance = 2;
  constexpr double kLdltAllowance = 8;
  constexpr double kBandBytesLimit = 1 << 30;
  constexpr int kCholmodFrom = 2500;  // unknowns
  const bool small = lower.rows() < kCholmodFrom;
  // The sparse flops from the node pattern of a FEM Hessian: a fraction of the analysis time.
  // CHOLMOD's come from its analysis, kept if it wins.
  std::optional<SparseMatrix> found;
  if (!nodes && (found = node_pattern(lower))) nodes = &*found;
  double sparse_flops = 0;
  auto estimate_sparse = [&] {
    if (nodes && small) {
      sparse_flops = ldlt_flops_by_nodes(*nodes);
    } else if (small) {
      CountingLdlt ldlt;
      ldlt.analyzePattern(lower);
      sparse_flops = ldlt.flops();
    } else {
      analyze_sparse(impl_->cholmod, lower, nodes);
      impl_->cholmod_analysed = true;
      sparse_flops = impl_->cholmod.flops();
    }
  };
  // The two analyses are independent: one on each core.
  tbb::parallel_invoke([&] { impl_->band.analyze(lower, nodes); }, estimate_sparse);
  const double allowance = small ? kLdltAllowance : kCholmodAllowance;
  const bool band = impl_->band.flops() <= allowance * sparse_flops &&
                    impl_->band.storage_bytes() <= kBandBytesLimit;
  if (!band) impl_->band = BandCholesky();       // its layout (an index per entry) is not needed
  if (band) impl_->cholmod = PermutedCholmod();  // nor CHOLMOD's analysis
  impl_->cholmod_analysed = impl_->cholmod_analysed && !band;
  return band ? Backend::Band : small ? Backend::SimplicialLDLT : Backend::CholmodSupernodal;
}

bool SparseCholesky::factorize(const SparseMatrix& lower) {
  constexpr int kThreadedBandFrom = 256;  // sub-diagonals; measured crossover on 2 cores (solve)
  switch (backend_) {
    case Backend::Band: {
      // The band factorization runs its own two threads over single-threaded BLAS calls
      // (band_factor.hpp); the solves keep OpenBLAS's threads on wide bands.
      use_blas_threads(false);
      const bool positive_definite = impl_->band.factorize(lower);
      use_blas_threads(impl_->band.bandwidth() >= kThreadedBandFrom);
      return positive_definite;
    }
    case Backend::CholmodSupernodal: {
      // Below PermutedCholmod::kOwnKernelsBelowFlops our own kernels factor, on this thread.
      // Above it CHOLMOD does: its OpenMP on one thread (serial_openmp.hpp), its BLAS on all
      // cores, for large factorizations are big dense blocks (docs/benchmarks.md, "CHOLMOD's
      // OpenMP threads": all cores 10-15 % faster from 8e9 flops, 5-15 % slower to 1.3e9).
      use_blas_threads(impl_->cholmod_blas_threads);
      SerialOpenMp serial;
      return impl_->cholmod.factorize(lower);
    }
    case Backend::SimplicialLDLT: break;
  }
  impl_->ldlt.factorize(lower);
  if (impl_->ldlt.info() != Eigen::Success) return false;
  // LDLᵀ also "succeeds" on indefinite matrices: positive definite means every pivot > 0,
  // and a pivot tiny next to the largest means the matrix is singular in double precision.
  const auto& D = impl_->ldlt.vectorD();
  return D.minCoeff() > 1e-13 * D.cwiseAbs().maxCoeff();
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& rhs) const {
  switch (backend_) {
    case Backend::Band: return impl_->band.solve(rhs);
    case Backend::CholmodSupernodal: return impl_->cholmod.solve(rhs);
    case Backend::SimplicialLDLT: break;
  }
  return impl_->ldlt.solve(rhs);
}

Eigen::VectorXd SparseCholesky::solve_preconditioner(const Eigen::VectorXd& rhs) const {
  if (backend_ == Backend::Band) return impl_->band.solve_single_precision(rhs);
  return solve(rhs);
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& rhs) const {
  switch (backend_) {
    case Backend::Band: return impl_->band.solve(rhs).col(0);
    case Backend::CholmodSupernodal: return impl_->cholmod.solve(rhs);
    case Backend::SimplicialLDLT: break;
  }
  return impl_->ldlt.solve(rhs);
}

}  // namespace shapectl
