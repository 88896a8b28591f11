#include <shapectl/linalg/sparse_cholesky.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <amd.h>
#include <cstdlib>
#include <stdexcept>
#include <tbb/parallel_invoke.h>
#include <utility>
#include <vector>

#include <shapectl/hand_off.hpp>
#include <shapectl/linalg/band_cholesky.hpp>
#include <shapectl/linalg/cholmod_library.hpp>
#include <shapectl/linalg/factorization.hpp>
#include <shapectl/linalg/node_pattern.hpp>
#include <shapectl/linalg/permuted_cholmod.hpp>
#include <shapectl/linalg/serial_openmp.hpp>
#include <shapectl/runtime/blas_threads.hpp>

namespace shapectl {

namespace {
using runtime::use_blas_threads;  // one thread, or one per core (runtime/blas_threads.hpp)

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

namespace {

// Eigen's simplicial LDLᵀ.
class LdltFactorization final : public Factorization {
 public:
  // Eigen's ordering copies the values with the pattern: the analysis gets a copy of the
  // pattern with zeros, so that statics can assemble the values beside it.
  void analyze(const SparseMatrix& lower, const SparseMatrix*) override {
    if (!lower.isCompressed()) return ldlt_.analyzePattern(lower);  // not statics' matrix
    SparseMatrix pattern(lower.rows(), lower.cols());
    pattern.resizeNonZeros(lower.nonZeros());
    std::copy_n(lower.outerIndexPtr(), lower.outerSize() + 1, pattern.outerIndexPtr());
    std::copy_n(lower.innerIndexPtr(), lower.nonZeros(), pattern.innerIndexPtr());
    std::fill_n(pattern.valuePtr(), lower.nonZeros(), 0.0);
    ldlt_.analyzePattern(pattern);
  }
  bool factorize(const SparseMatrix& lower) override {
    ldlt_.factorize(lower);
    if (ldlt_.info() != Eigen::Success) return false;
    // LDLᵀ also "succeeds" on indefinite matrices: positive definite means every pivot > 0,
    // and a pivot tiny next to the largest means the matrix is singular in double precision.
    const auto& D = ldlt_.vectorD();
    return D.minCoeff() > 1e-13 * D.cwiseAbs().maxCoeff();
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override { return ldlt_.solve(rhs); }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const override { return ldlt_.solve(rhs); }

 private:
  CountingLdlt ldlt_;
};

// The band (band_cholesky.hpp), possibly analysed already by the automatic choice.
class BandFactorization final : public Factorization {
 public:
  explicit BandFactorization(BandCholesky band = {}) : band_(std::move(band)) {}
  // The band finds the node pattern itself (as a fixed band always has).
  void analyze(const SparseMatrix& lower, const SparseMatrix*) override { band_.analyze(lower); }
  bool factorize(const SparseMatrix& lower) override {
    constexpr int kThreadedBandFrom = 256;  // sub-diagonals; measured crossover on 2 cores (solve)
    // The band factorization runs its own two threads over single-threaded BLAS calls
    // (band_factor.hpp); the solves keep OpenBLAS's threads on wide bands.
    use_blas_threads(false);
    const bool positive_definite = band_.factorize(lower);
    use_blas_threads(band_.bandwidth() >= kThreadedBandFrom);
    return positive_definite;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override {
    return band_.solve(rhs).col(0);
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const override { return band_.solve(rhs); }
  // The band's factor in single precision (BandCholesky::solve_single_precision).
  Eigen::VectorXd solve_preconditioner(const Eigen::VectorXd& rhs) const override {
    return band_.solve_single_precision(rhs);
  }

 private:
  BandCholesky band_;
};

// Supernodal LLᵀ on CHOLMOD's analysis (permuted_cholmod.hpp), possibly analysed already by the
// automatic choice.
class CholmodFactorization final : public Factorization {
 public:
  CholmodFactorization() = default;
  explicit CholmodFactorization(PermutedCholmod analysed) : cholmod_(std::move(analysed)) {
    blas_threads_ = !cholmod_.own_kernels();
  }
  void analyze(const SparseMatrix& lower, const SparseMatrix* nodes) override {
    analyze_sparse(cholmod_, lower, nodes);
    blas_threads_ = !cholmod_.own_kernels();
  }
  bool factorize(const SparseMatrix& lower) override {
    // Below PermutedCholmod::kOwnKernelsBelowFlops our own kernels factor, on this thread.
    // Above it CHOLMOD does: its OpenMP on one thread (serial_openmp.hpp), its BLAS on all
    // cores, for large factorizations are big dense blocks (docs/benchmarks.md, "CHOLMOD's
    // OpenMP threads": all cores 10-15 % faster from 8e9 flops, 5-15 % slower to 1.3e9).
    use_blas_threads(blas_threads_);
    SerialOpenMp serial;
    return cholmod_.factorize(lower);
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override { return cholmod_.solve(rhs); }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const override { return cholmod_.solve(rhs); }
  // CHOLMOD's solve is not cheap (SparseCholesky::cheap_to_solve).
  bool cheap_to_solve() const override { return false; }

 private:
  PermutedCholmod cholmod_;
  bool blas_threads_ = false;
};

// CHOLMOD on its own (cholmod_library.hpp), its BLAS on as many threads as where CHOLMOD
// factors for `cholmod`: all cores from PermutedCholmod::kOwnKernelsBelowFlops, else one (on a
// loaded machine OpenBLAS's spinning threads made a sweep of 1.3k-unknown solves 12x slower).
class CholmodLibraryFactorization final : public CholmodLibrary {
 public:
  bool factorize(const SparseMatrix& lower) override {
    use_blas_threads(flops() >= PermutedCholmod::kOwnKernelsBelowFlops);
    return CholmodLibrary::factorize(lower);
  }
};

std::unique_ptr<Factorization> make_factorization(CholeskyBackend backend) {
  switch (backend) {
    case CholeskyBackend::SimplicialLDLT: return std::make_unique<LdltFactorization>();
    case CholeskyBackend::Band: return std::make_unique<BandFactorization>();
    case CholeskyBackend::CholmodSupernodal: return std::make_unique<CholmodFactorization>();
    case CholeskyBackend::CholmodLibrary: return std::make_unique<CholmodLibraryFactorization>();
  }
  throw std::logic_error("SparseCholesky: unknown back-end");
}

}  // namespace

SparseCholesky::SparseCholesky(std::optional<Backend> backend)
    : automatic_(!backend), backend_(backend.value_or(Backend::SimplicialLDLT)) {
  if (backend) factorization_ = make_factorization(*backend);
}

SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze(const SparseMatrix& lower, const SparseMatrix* nodes) {
  if (automatic_) factorization_ = choose(lower, nodes);
  else factorization_->analyze(lower, nodes);
}

std::unique_ptr<Factorization> SparseCholesky::choose(const SparseMatrix& lower,
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
  BandCholesky band;
  PermutedCholmod cholmod;
  double sparse_flops = 0;
  auto estimate_sparse = [&] {
    if (nodes && small) {
      sparse_flops = ldlt_flops_by_nodes(*nodes);
    } else if (small) {
      CountingLdlt ldlt;
      ldlt.analyzePattern(lower);
      sparse_flops = ldlt.flops();
    } else {
      analyze_sparse(cholmod, lower, nodes);
      sparse_flops = cholmod.flops();
    }
  };
  // The two analyses are independent: one on each core.
  HandOff hand_off;
  tbb::parallel_invoke(hand_off([&] { band.analyze(lower, nodes); }), hand_off(estimate_sparse));
  hand_off.joined();
  const double allowance = small ? kLdltAllowance : kCholmodAllowance;
  if (band.flops() <= allowance * sparse_flops && band.storage_bytes() <= kBandBytesLimit) {
    backend_ = Backend::Band;
    return std::make_unique<BandFactorization>(std::move(band));
  }
  if (!small) {
    backend_ = Backend::CholmodSupernodal;
    return std::make_unique<CholmodFactorization>(std::move(cholmod));
  }
  backend_ = Backend::SimplicialLDLT;
  auto ldlt = std::make_unique<LdltFactorization>();
  ldlt->analyze(lower, nodes);
  return ldlt;
}

bool SparseCholesky::factorize(const SparseMatrix& lower) {
  return factorization_->factorize(lower);
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& rhs) const {
  return factorization_->solve(rhs);
}

Eigen::VectorXd SparseCholesky::solve_preconditioner(const Eigen::VectorXd& rhs) const {
  return factorization_->solve_preconditioner(rhs);
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& rhs) const {
  return factorization_->solve(rhs);
}

bool SparseCholesky::cheap_to_solve() const { return factorization_->cheap_to_solve(); }

}  // namespace shapectl
