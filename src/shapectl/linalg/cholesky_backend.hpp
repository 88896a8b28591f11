#pragma once
// Which sparse Cholesky factors the statics Hessian (linalg/sparse_cholesky.hpp), in a header of
// its own: a Scene names one without pulling in the solver.
#include <string_view>

namespace shapectl {

// Simplicial LDLᵀ (Eigen), a dense band after reverse Cuthill–McKee (LAPACK), supernodal LLᵀ
// (CHOLMOD).
enum class CholeskyBackend { SimplicialLDLT, Band, CholmodSupernodal };
// Its name in scene files ("statics.linear_solver"): "ldlt", "band", "cholmod".
const char* to_string(CholeskyBackend backend);
bool parse(std::string_view name, CholeskyBackend* backend);

}  // namespace shapectl
