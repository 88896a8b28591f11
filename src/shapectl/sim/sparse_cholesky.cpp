#include <shapectl/sim/sparse_cholesky.hpp>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <tbb/parallel_invoke.h>

#include <shapectl/sim/band_cholesky.hpp>
#include <shapectl/sim/node_pattern.hpp>
#include <shapectl/sim/permuted_cholmod.hpp>
#include <shapectl/sim/serial_openmp.hpp>

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

// CHOLMOD's supernodal LLᵀ, for its analysis: the flops and the fill-reducing permutation.
struct CholmodLlt : Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
  // perm[k]: the matrix's row and column that comes k-th.
  std::vector<int> permutation() const {
    const int* p = static_cast<const int*>(m_cholmodFactor->Perm);
    return {p, p + m_cholmodFactor->n};
  }
};

constexpr int kCholmodDefault = -1;  // CHOLMOD's own strategy instead of one ordering

// Flops of CHOLMOD's factorization of `lower` with an ordering method; *entries: of the factor,
// *perm (if given): its permutation.
double cholmod_flops(const SparseMatrix& lower, int ordering, double* entries,
                     std::vector<int>* perm = nullptr) {
  SerialOpenMp serial;
  CholmodLlt cholmod;
  cholmod.cholmod().print = 0;
  if (ordering != kCholmodDefault) {
    cholmod.cholmod().nmethods = 1;
    cholmod.cholmod().method[0].ordering = ordering;
  }
  cholmod.analyzePattern(lower);
  *entries = cholmod.cholmod().lnz;
  if (perm) *perm = cholmod.permutation();
  return cholmod.cholmod().fl;
}

// Flops of the sparse factorization CHOLMOD would make, without its analysis of the dofs:
// found on the node pattern (node_pattern.hpp) by CHOLMOD's own default rule, AMD and then
// METIS too where AMD's factor is dense (over 500 flops per entry of it and 5 entries per
// entry of the matrix; on the dofs, each node's ratios are 3x and 1x its own). Within 4 % of
// the dof analysis on the meshes of docs/benchmarks.md, "the back-end choice, again".
// *order: the winning ordering of the nodes (reverse_cuthill_mckee's convention).
double cholmod_flops_by_nodes(const SparseMatrix& nodes, std::vector<int>* order) {
  double entries = 0;
  const double amd = 27 * cholmod_flops(nodes, CHOLMOD_AMD, &entries, order);
  const bool dense = amd >= 500 * 9 * entries && entries >= 5 * nodes.nonZeros();
  if (!dense) return amd;
  std::vector<int> metis_order;
  const double metis = 27 * cholmod_flops(nodes, CHOLMOD_METIS, &entries, &metis_order);
  if (metis >= amd) return amd;
  *order = std::move(metis_order);
  return metis;
}

// The same for Eigen's LDLᵀ (AMD ordering).
double ldlt_flops_by_nodes(const SparseMatrix& nodes) {
  CountingLdlt ldlt;
  ldlt.analyzePattern(nodes);
  return 27 * ldlt.flops();
}
}  // namespace

struct SparseCholesky::Impl {
  CountingLdlt ldlt;
  BandCholesky band;
  PermutedCholmod cholmod;
  bool cholmod_blas_threads = false;  // see factorize()
  // From choose(): CHOLMOD's ordering of the nodes, expanded to the dofs; empty: none.
  std::vector<int> cholmod_order;
};

SparseCholesky::SparseCholesky(std::optional<Backend> backend)
    : automatic_(!backend),
      backend_(backend.value_or(Backend::SimplicialLDLT)),
      impl_(std::make_unique<Impl>()) {}

SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze(const SparseMatrix& lower) {
  if (automatic_) backend_ = choose(lower);
  switch (backend_) {
    case Backend::SimplicialLDLT: impl_->ldlt.analyzePattern(lower); break;
    case Backend::Band:
      if (!automatic_) impl_->band.analyze(lower);  // choose() did
      break;
    case Backend::CholmodSupernodal: {
      SerialOpenMp serial;
      // The order the choice found on the nodes (none when the backend is fixed): CHOLMOD's
      // own analysis of the dofs would order their nine times larger graph again (7 of 12 ms
      // on a 12.8k-tet TetGen bar).
      impl_->cholmod.analyze(lower, std::move(impl_->cholmod_order));
      impl_->cholmod_order.clear();
      impl_->cholmod_blas_threads = !impl_->cholmod.own_kernels();
      break;
    }
  }
}

SparseCholesky::Backend SparseCholesky::choose(const SparseMatrix& lower) {
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
  const std::optional<SparseMatrix> nodes = node_pattern(lower);
  double sparse_flops = 0;
  auto estimate_sparse = [&] {
    if (nodes) {
      std::vector<int> order;
      sparse_flops = small ? ldlt_flops_by_nodes(*nodes) : cholmod_flops_by_nodes(*nodes, &order);
      if (!order.empty()) impl_->cholmod_order = dof_order(order);
    } else if (small) {
      CountingLdlt ldlt;
      ldlt.analyzePattern(lower);
      sparse_flops = ldlt.flops();
    } else {
      double entries = 0;
      sparse_flops = cholmod_flops(lower, kCholmodDefault, &entries);
    }
  };
  // The two analyses are independent: one on each core.
  tbb::parallel_invoke([&] { impl_->band.analyze(lower, nodes); }, estimate_sparse);
  const double allowance = small ? kLdltAllowance : kCholmodAllowance;
  const bool band = impl_->band.flops() <= allowance * sparse_flops &&
                    impl_->band.storage_bytes() <= kBandBytesLimit;
  if (!band) impl_->band = BandCholesky();  // its layout (an index per entry) is not needed
  if (band || small) impl_->cholmod_order.clear();
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
