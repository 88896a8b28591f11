#include <shapectl/linalg/cholmod_library.hpp>

#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

#include <shapectl/linalg/cholmod_view.hpp>
#include <shapectl/linalg/serial_openmp.hpp>

namespace shapectl {

struct CholmodLibrary::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  bool factored = false;
  std::mutex solve_mutex;

  Impl() {
    cholmod_start(&common);
    common.print = 0;  // not positive definite is an expected outcome, not something to print
  }
  ~Impl() {
    free_factor();
    cholmod_finish(&common);
  }
  void free_factor() {
    if (factor) cholmod_free_factor(&factor, &common);
    factored = false;
  }
};

CholmodLibrary::CholmodLibrary() : impl_(std::make_unique<Impl>()) {}
CholmodLibrary::~CholmodLibrary() = default;

void CholmodLibrary::analyze(const SparseMatrix& lower, const SparseMatrix*) {
  Impl& m = *impl_;
  m.free_factor();
  SerialOpenMp serial;  // CHOLMOD's fixed num_threads(4) (serial_openmp.hpp)
  cholmod_sparse a = cholmod_lower_view(lower);
  m.factor = cholmod_analyze(&a, &m.common);
  throw_if_cholmod_failed(m.factor != nullptr, "analyse the matrix");
}

double CholmodLibrary::flops() const { return impl_->common.fl; }

bool CholmodLibrary::factorize(const SparseMatrix& lower) {
  Impl& m = *impl_;
  if (!m.factor) throw std::logic_error("CholmodLibrary: analyse before factorizing");
  m.factored = false;
  // CHOLMOD factors a matrix with a NaN "successfully".
  const double* values = lower.valuePtr();
  for (Eigen::Index k = 0; k < lower.nonZeros(); ++k)
    if (!std::isfinite(values[k])) return false;
  SerialOpenMp serial;
  cholmod_sparse a = cholmod_lower_view(lower);
  // On a matrix that is not positive definite CHOLMOD stops at column `minor` < n.
  m.factored = cholmod_factorize(&a, m.factor, &m.common) && m.factor->minor == m.factor->n;
  return m.factored;
}

Eigen::MatrixXd CholmodLibrary::solve(const Eigen::MatrixXd& rhs) const {
  Impl& m = *impl_;
  if (!m.factored) throw std::logic_error("CholmodLibrary: solve after a successful factorization");
  if (rhs.rows() != static_cast<Eigen::Index>(m.factor->n))
    throw std::logic_error("CholmodLibrary: solve as many rows as the matrix has");
  if (rhs.cols() == 0) return rhs;
  Eigen::MatrixXd b = rhs;
  cholmod_dense b_view = Eigen::viewAsCholmod(b);
  const std::lock_guard lock(m.solve_mutex);
  SerialOpenMp serial;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, m.factor, &b_view, &m.common);
  throw_if_cholmod_failed(x != nullptr, "solve");
  Eigen::MatrixXd result =
      Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), rhs.rows(), rhs.cols());
  cholmod_free_dense(&x, &m.common);
  return result;
}

Eigen::VectorXd CholmodLibrary::solve(const Eigen::VectorXd& rhs) const {
  return solve(Eigen::MatrixXd(rhs)).col(0);
}

}  // namespace shapectl
