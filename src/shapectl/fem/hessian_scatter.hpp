#pragma once
// The scatter map of a Hessian whose elements are fixed: the lower-triangle compressed (CSC)
// pattern of every element block (fixed dofs' rows and columns dropped, their diagonal kept),
// and for each entry of each element block the value index it adds into. Built once per set of
// elements; assembling then adds element blocks straight into the matrix values, no triplets.
// Each term's elements are split into colours whose elements share no node, so the blocks of
// one colour are computed and added on all cores without two threads touching one value (and
// every value sums its contributions in the same order on every run).
#include <cstddef>
#include <memory>
#include <vector>

#include <shapectl/fem/element_hessians.hpp>
#include <shapectl/types.hpp>

namespace shapectl {

class HessianScatter {
 public:
  // elements[t]: the elements of term t. fixed_dof: size dof_count, nonzero where the dof is
  // held (its row and column are left out; only its diagonal stays). Writes the pattern, with
  // zero values, to `pattern` (dof_count × dof_count, lower triangle, compressed).
  HessianScatter(int dof_count, const std::vector<char>& fixed_dof,
                 const std::vector<ElementNodes>& elements, SparseMatrix& pattern);

  // Runs `kernel` on every element of term t, colour by colour, the elements of a colour in
  // parallel, and adds each block into `values` (the pattern's value array).
  void add_blocks(std::size_t term, const ElementKernel& kernel, double* values) const;
  // The pattern's node pairs: (i, j), i ≥ j, where some entry between their dofs lands; every
  // node's diagonal. nodes × nodes, lower triangle, compressed, zero values (as node_pattern()
  // in linalg/node_pattern.hpp makes it from the dof pattern, for fill-reducing orders).
  const SparseMatrix& node_pattern() const { return node_pattern_; }
  // Value index of the diagonal entry of each fixed dof.
  const std::vector<int>& fixed_diagonal_slots() const { return fixed_diagonal_slots_; }

 private:
  struct Term {
    int first_element = 0;            // global index of the term's first element
    std::vector<int> colour_offsets;  // colour c: by_colour[colour_offsets[c] …]
    std::vector<int> by_colour;       // the term's elements (local indices), colour by colour
  };
  void build_pattern(int dof_count, const std::vector<char>& fixed_dof,
                     const std::vector<ElementNodes>& elements, SparseMatrix& pattern);
  std::vector<Term> terms_;
  // Adds global element g's block into the values.
  void add_block(int g, const double* block, double* values) const;
  // Where the kept entries of an element's block go. Only entries that land (lower triangle,
  // free dofs) are listed: no test in the hot loop. Between two free nodes i ≥ j, the 3×3 block
  // whose column c starts at block[block_column + c·3k] adds into column 3j + c from rows r = c
  // on (i = j) or r = 0 (i > j). Node j's columns hold the same rows from the diagonal on, so
  // column 3j + c is column 3j (column_length entries) shifted: row r of the block goes to
  // values[start + c·column_length - c(c+1)/2 + r]. 16 bytes for 9 entries.
  struct NodePair {
    int block_column, start, column_length;
    bool diagonal;
  };
  // One entry with a partly held node: value index `slot` gets block[entry].
  struct Entry {
    int entry, slot;
  };
  std::vector<int> block_dofs_;     // global element g: 3k
  std::vector<int> pair_offsets_;   // global element g: pairs_[pair_offsets_[g] …]
  std::vector<int> entry_offsets_;  // global element g: entries_[entry_offsets_[g] …]
  std::unique_ptr<NodePair[]> pairs_;
  std::unique_ptr<Entry[]> entries_;
  std::vector<int> fixed_diagonal_slots_;
  SparseMatrix node_pattern_;
};

}  // namespace shapectl
