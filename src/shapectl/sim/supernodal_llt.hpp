#pragma once
// The numeric supernodal LLᵀ on a pattern CHOLMOD has analysed, and solves with it: our own
// kernels on CHOLMOD's symbolic factor (its supernodes, their rows, where their values go).
//
// Why not cholmod_factorize and cholmod_solve2: they make a few BLAS calls per supernode, and
// our factors are many small supernodes (a 12.8k-tet TetGen bar: 1,321 of 7.8 columns on
// average, a 4.3k-tet TetGen frame: 1,182 of 4), so much of their time went to call overhead.
// With Eigen's kernels inlined, a TetGen frame factors 2.1x faster, a TetGen bar 1.27x, a
// 60x60x1 plate 1.2x; one right-hand side solves 1.4-2x faster, several as fast
// (docs/benchmarks.md, "session 8"). Large factorizations, whose BLAS calls use all cores,
// stay with CHOLMOD (permuted_cholmod.hpp). The solves need no cholmod_common, so threads may
// share a factor.
#include <Eigen/Core>
#include <cholmod.h>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// Which thread factorize_supernodal gives each supernode: 0 or 1 for the supernodes of two
// disjoint subtrees of the elimination tree, factored at once; 2 for those above both, after
// them. All 0 where the tree does not split into two teams of a tenth of the work or more, or
// the factorization is small. Depends on the analysis only: find it once per pattern.
// `factor`: supernodal, symbolic or numeric (else std::logic_error).
std::vector<int> supernodal_teams(const cholmod_factor& factor);

// Left-looking supernodal Cholesky of `lower` (lower triangle, compressed, of the pattern
// `factor` was analysed for, in its natural order) into factor.x, on two threads as `teams`
// (supernodal_teams of this factor) says. `factor`: supernodal, LLᵀ, real, its values
// allocated (cholmod_change_factor). False if `lower` is not (numerically) positive definite
// (a pivot ≤ 0) or not finite; the factor is then unusable.
bool factorize_supernodal(const SparseMatrix& lower, cholmod_factor& factor,
                          const std::vector<int>& teams);

// Solves L Lᵀ x = b in place, in the factor's order. `factor`: numeric, supernodal, LLᵀ, real
// (else std::logic_error).
void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::VectorXd& x);
void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::MatrixXd& x);

}  // namespace shapectl
