#pragma once
// Blocked Cholesky factorization of a symmetric positive definite band matrix, in place in
// LAPACK's lower band storage (as dpbtrf with uplo 'L' and ldab = kd + 1 leaves it, so
// dpbtrs and the other band solves read its result unchanged).

namespace shapectl {

// Factors the n × n band with kd sub-diagonals stored in `ab` ((kd + 1) × n, column j holds
// A(j .. j + kd, j)) into L, `block` columns at a time (clamped to 1 .. kd). With
// `two_threads` each block column's trailing update is shared between the calling thread and
// one TBB task, which call BLAS at the same time: OpenBLAS should then be single-threaded
// (SparseCholesky sees to it), or its threads compete with these.
// Returns false as soon as a diagonal block (dpotrf) is found not positive definite: nothing
// to its right has been factored then, and `ab` must not be used.
bool factor_band(double* ab, int n, int kd, int block, bool two_threads);

}  // namespace shapectl
