#pragma once
// Solves L Lᵀ x = b in place with a CHOLMOD supernodal factor, in the factor's own order.
//
// Why not cholmod_solve2: it makes a few BLAS calls per supernode, and our factors are many
// small supernodes (a 12.8k-tet TetGen bar: 1,321 of 7.8 columns on average), so a solve with
// one right-hand side spent about half its time in call overhead. Eigen's kernels, inlined
// here, solve one right-hand side 1.4-2x faster and several as fast (docs/benchmarks.md,
// "session 8"). It also needs no cholmod_common, so threads may share the factor freely.
#include <Eigen/Core>
#include <cholmod.h>

namespace shapectl {

// `factor`: numeric, supernodal, LLᵀ, real (else std::logic_error).
void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::VectorXd& x);
void solve_supernodal_in_place(const cholmod_factor& factor, Eigen::MatrixXd& x);

}  // namespace shapectl
