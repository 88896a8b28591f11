#include <shapectl/sim/sparse_cholesky.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <atomic>
#include <cstdlib>

#include <shapectl/sim/band_cholesky.hpp>

namespace shapectl {

// OpenBLAS's thread control, if the BLAS is OpenBLAS (weak: absent otherwise).
extern "C" void openblas_set_num_threads(int threads) __attribute__((weak));
extern "C" int openblas_get_num_procs() __attribute__((weak));

namespace {
// OpenBLAS threads pay off only for large dense blocks; on small ones they cost more in
// hand-offs and spinning than they save (`shapectl bench` on the YuMi bar: 10 % faster with
// one thread; a 50k-tet band factorization: 22 % slower). OPENBLAS_NUM_THREADS, if set, wins.
void use_blas_threads(bool many) {
  static const bool user_set = std::getenv("OPENBLAS_NUM_THREADS") != nullptr;
  static std::atomic<int> current{0};
  if (user_set || !openblas_set_num_threads || !openblas_get_num_procs) return;
  const int threads = many ? openblas_get_num_procs() : 1;
  if (current.exchange(threads) != threads) openblas_set_num_threads(threads);
}

// Eigen's LDLᵀ, plus the flop count of its factorization from the symbolic analysis.
struct CountingLdlt : Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> {
  double flops() const {
    double f = 0;
    for (int j = 0; j < m_nonZerosPerCol.size(); ++j)
      f += double(m_nonZerosPerCol[j] + 1) * (m_nonZerosPerCol[j] + 1);
    return f;
  }
};
}  // namespace

struct SparseCholesky::Impl {
  CountingLdlt ldlt;
  BandCholesky band;
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> cholmod;
};

SparseCholesky::SparseCholesky(std::optional<Backend> backend)
    : automatic_(!backend),
      backend_(backend.value_or(Backend::SimplicialLDLT)),
      impl_(std::make_unique<Impl>()) {
  // Not positive definite is an expected outcome (we fall back), not something to print.
  impl_->cholmod.cholmod().print = 0;
}

SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze(const SparseMatrix& lower) {
  if (automatic_) {
    // The band Cholesky after reverse Cuthill–McKee runs at several times the flop rate of
    // Eigen's simplicial LDLᵀ and of CHOLMOD's supernodal one, so it is the faster while it
    // does at most a few times their flops. Measured on 2 cores (docs/benchmarks.md, "the
    // back-end choice"): up to 2.5x at any width (box meshes of 400 to 50k tets), and up to
    // 8x while the band is at most 1,000 sub-diagonals wide: TetGen bars of 12.8k and 51k
    // tets (5.4-5.5x the flops, bands 336 and 746 wide) solve 1.75x and 1.25x faster with it,
    // a 14-cell cube (2.8x, ~700) 1.6x; a TetGen cube (21x) or a 24-cell box cube (4.1x,
    // ~1,900 wide) 1.3-2x slower. Otherwise (or over 1 GiB of band) the sparse one: LDLᵀ for
    // small systems, CHOLMOD for large ones.
    constexpr double kBandFlopAllowance = 2.5;
    constexpr double kNarrowBandFlopAllowance = 8;
    constexpr int kNarrowBand = 1000;  // sub-diagonals
    constexpr double kBandBytesLimit = 1 << 30;
    constexpr int kCholmodFrom = 2500;  // unknowns
    const bool small = lower.rows() < kCholmodFrom;
    impl_->band.analyze(lower);
    double sparse_flops = 0;
    if (small) {
      impl_->ldlt.analyzePattern(lower);
      sparse_flops = impl_->ldlt.flops();
    } else {
      impl_->cholmod.analyzePattern(lower);
      sparse_flops = impl_->cholmod.cholmod().fl;
    }
    const double allowance =
        impl_->band.bandwidth() <= kNarrowBand ? kNarrowBandFlopAllowance : kBandFlopAllowance;
    const bool band = impl_->band.flops() <= allowance * sparse_flops &&
                      impl_->band.storage_bytes() <= kBandBytesLimit;
    backend_ = band ? Backend::Band : small ? Backend::SimplicialLDLT : Backend::CholmodSupernodal;
    return;
  }
  switch (backend_) {
    case Backend::SimplicialLDLT: impl_->ldlt.analyzePattern(lower); break;
    case Backend::Band: impl_->band.analyze(lower); break;
    case Backend::CholmodSupernodal: impl_->cholmod.analyzePattern(lower); break;
  }
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
    case Backend::CholmodSupernodal:
      use_blas_threads(true);
      impl_->cholmod.factorize(lower);
      return impl_->cholmod.info() == Eigen::Success;
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
