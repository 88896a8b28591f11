#pragma once
// What PermutedCholmod and CholmodLibrary hand CHOLMOD: a view of a lower-triangle matrix as a
// symmetric one, and a clear error where CHOLMOD returns nothing.
#include <Eigen/CholmodSupport>
#include <stdexcept>
#include <string>

#include <shapectl/types.hpp>

namespace shapectl {

inline cholmod_sparse cholmod_lower_view(const SparseMatrix& lower) {
  return Eigen::viewAsCholmod(lower.selfadjointView<Eigen::Lower>());
}

inline void throw_if_cholmod_failed(bool ok, const char* what) {
  if (!ok) throw std::runtime_error(std::string("CHOLMOD could not ") + what + " (out of memory?)");
}

}  // namespace shapectl
