#pragma once
// The numeric supernodal LLᵀ on a supernodal pattern (supernodal_pattern.hpp: found by
// CHOLMOD's analysis, of the dofs or of the nodes), and solves with it: our own kernels.
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
#include <vector>

#include <shapectl/linalg/supernodal_pattern.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

// Which thread factorize_supernodal gives each supernode: 0 or 1 for the supernodes of two
// disjoint subtrees of the elimination tree, factored at once; 2 for those above both, after
// them. All 0 where the tree does not split into two teams of a tenth of the work or more, or
// the factorization is small. Depends on the pattern only: find it once per analysis.
std::vector<int> supernodal_teams(const SupernodalPattern& pattern);

// Left-looking supernodal Cholesky of `lower` (lower triangle, compressed, within `pattern`'s
// structure, in its natural order) into `values` (pattern.value_count() of them), on two
// threads as `teams` (supernodal_teams of this pattern) says. False if `lower` is not
// (numerically) positive definite (a pivot ≤ 0) or not finite; the factor is then unusable.
bool factorize_supernodal(const SparseMatrix& lower, const SupernodalPattern& pattern,
                          const std::vector<int>& teams, double* values);

// Solves L Lᵀ x = b in place, in the factor's order, with the factor's `values` (ours, or
// CHOLMOD's numeric supernodal LLᵀ with its pattern); with `teams` (supernodal_teams of the
// pattern), the two subtrees on two threads. Rows other than pattern.size(), no values or a
// teams list of another size: std::logic_error.
void solve_supernodal_in_place(const SupernodalPattern& pattern, const double* values,
                               Eigen::VectorXd& x, const std::vector<int>& teams = {});
void solve_supernodal_in_place(const SupernodalPattern& pattern, const double* values,
                               Eigen::MatrixXd& x, const std::vector<int>& teams = {});

}  // namespace shapectl
