#pragma once
// Cholesky factorization of a sparse SPD matrix as a dense band: the unknowns are renumbered
// by reverse Cuthill–McKee, which makes the band of an elongated mesh (a bar, a frame) narrow,
// and a blocked band Cholesky (BLAS-3) factors it: LAPACK's dpbtrf for narrow bands, our own
// two-thread one for wide bands (band_factor.hpp). On such meshes this runs
// several times faster than a simplicial sparse factorization of the same matrix, although
// it does more flops: dense kernels use the vector units, scattered sparse updates do not.
#include <optional>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// Reverse Cuthill–McKee ordering of the symmetric pattern whose lower triangle is `lower`:
// order[k] is the old index of the k-th unknown. Each connected part starts from a
// pseudo-peripheral vertex.
std::vector<int> reverse_cuthill_mckee(const SparseMatrix& lower);

class BandCholesky {
 public:
  // Ordering and band layout for this pattern (lower triangle, compressed).
  void analyze(const SparseMatrix& lower);
  // The same with the node pattern of `lower` (node_pattern.hpp) already found, or null.
  void analyze(const SparseMatrix& lower, const SparseMatrix* nodes);
  int bandwidth() const { return bandwidth_; }  // sub-diagonals in the band
  // Floating-point operations of one factorization, ~ Σ (column length)².
  double flops() const;
  // Memory the band takes (allocated by the first factorize()).
  double storage_bytes() const { return 8.0 * (bandwidth_ + 1) * size_; }
  // Numeric factorization; false if the matrix is not (numerically) positive definite.
  // The matrix must have the analyzed pattern.
  bool factorize(const SparseMatrix& lower);
  // Solves with the factor. Many right-hand sides go through a blocked level-3 substitution
  // that reads the band once per sweep for all of them; one or two go through LAPACK's dpbtrs.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;
  // Solves with the factor rounded to single precision (LAPACK's stbsv): half the memory a
  // one-column solve streams, and a solve is memory-bound. For preconditioning and chord steps
  // only, whose results the true residual checks. The rounded copy is made by the first call
  // after each factorization; like solve(), calls take turns (the caller's lock).
  Eigen::VectorXd solve_single_precision(const Eigen::VectorXd& rhs) const;

 private:
  int size_ = 0;
  int bandwidth_ = 0;
  std::vector<int> new_index_;           // new_index_[old] = position in the band
  std::vector<int> slot_;                // band storage index of each stored entry of `lower`
  Eigen::VectorXd band_;                 // LAPACK lower band storage, (bandwidth_ + 1) × size_
  mutable Eigen::VectorXf band_single_;  // band_ rounded, when band_single_current_
  mutable bool band_single_current_ = false;
};

}  // namespace shapectl
