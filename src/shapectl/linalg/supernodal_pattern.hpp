#pragma once
// The structure of a supernodal Cholesky factor L, its symbolic analysis: which columns each
// supernode has, which rows, and where its values go. Supernode k is the columns
// first_column[k] … first_column[k + 1] − 1 of L, stored as one dense column-major block at
// values[value_starts[k] …] whose rows are row_index[row_starts[k] …] (its own columns first,
// then the rows below them, ascending). Our kernels (supernodal_llt.hpp) factor and solve on it.
#include <cholmod.h>
#include <cstddef>
#include <vector>

namespace shapectl {

struct SupernodalPattern {
  std::vector<int> first_column{0}, row_starts{0}, value_starts{0}, row_index;

  int count() const { return static_cast<int>(first_column.size()) - 1; }
  int size() const { return first_column.back(); }  // L is size × size
  std::size_t value_count() const { return static_cast<std::size_t>(value_starts.back()); }
  int columns(int k) const { return first_column[k + 1] - first_column[k]; }
  int rows(int k) const { return row_starts[k + 1] - row_starts[k]; }
  // Floating-point operations of the numeric factorization: Σ over L's columns of (entries)².
  double flops() const;
};

// CHOLMOD's supernodal factor's structure, copied (symbolic or numeric; else std::logic_error).
SupernodalPattern supernodal_pattern(const cholmod_factor& factor);

// The factor's structure for a matrix made of dense `block` × `block` blocks whose pattern of
// blocks has the factor structure `blocks`: every row and column of it becomes `block`
// consecutive ones (a FEM Hessian's 3×3 node blocks: the factor of its node pattern, found at a
// ninth of the entries, gives the factor of the dofs).
SupernodalPattern expand_blocks(const SupernodalPattern& blocks, int block);

}  // namespace shapectl
