#pragma once
// Which sparse Cholesky factors the statics Hessian (linalg/sparse_cholesky.hpp), in a header of
// its own: a Scene names one without pulling in the solver.
#include <string>
#include <string_view>

namespace shapectl {

// Simplicial LDLᵀ (Eigen), a dense band after reverse Cuthill–McKee (LAPACK), supernodal LLᵀ
// (CHOLMOD's analysis, our kernels), CHOLMOD on its own (cholmod_library.hpp; never automatic).
enum class CholeskyBackend { SimplicialLDLT, Band, CholmodSupernodal, CholmodLibrary };
// Its name in scene files ("statics.linear_solver"): "ldlt", "band", "cholmod",
// "cholmod-library".
const char* to_string(CholeskyBackend backend);
bool parse(std::string_view name, CholeskyBackend* backend);
// The names a user may give, "auto" (the choice from the matrix) first, quoted, for messages:
// "auto", "ldlt", "band", "cholmod" or "cholmod-library".
std::string linear_solver_choices();

}  // namespace shapectl
