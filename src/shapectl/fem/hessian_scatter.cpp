#include <shapectl/fem/hessian_scatter.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace shapectl {

namespace {

// Greedy colouring: each element takes the lowest colour none of its nodes has yet. Colours
// are tracked 64 at a time in a bit mask per node; elements that find all 64 taken wait for a
// next round with fresh masks (only meshes with nodes in more than 64 elements need one).
std::vector<int> greedy_colours(const ElementNodes& elements, int node_count) {
  std::vector<int> colour(elements.size(), -1);
  std::vector<int> waiting(elements.size());
  for (std::size_t e = 0; e < waiting.size(); ++e) waiting[e] = static_cast<int>(e);
  std::vector<std::uint64_t> used;
  for (int round = 0; !waiting.empty(); ++round) {
    used.assign(node_count, 0);
    std::vector<int> next;
    for (const int e : waiting) {
      std::uint64_t taken = 0;
      for (int a = 0; a < elements.node_count(e); ++a) taken |= used[elements.begin(e)[a]];
      if (taken == ~std::uint64_t{0}) {
        next.push_back(e);
        continue;
      }
      const int c = __builtin_ctzll(~taken);
      colour[e] = 64 * round + c;
      for (int a = 0; a < elements.node_count(e); ++a)
        used[elements.begin(e)[a]] |= std::uint64_t{1} << c;
    }
    waiting = std::move(next);
  }
  return colour;
}

constexpr std::size_t kColourGrain = 32;

}  // namespace

HessianScatter::HessianScatter(int dof_count, const std::vector<char>& fixed_dof,
                               const std::vector<ElementNodes>& elements, SparseMatrix& pattern) {
  const int node_count = dof_count / 3;
  int first = 0;
  for (const ElementNodes& term_elements : elements) {
    Term term;
    term.first_element = first;
    first += static_cast<int>(term_elements.size());
    for (std::size_t e = 0; e < term_elements.size(); ++e) {
      const int dofs = 3 * term_elements.node_count(e);
      block_sizes_.push_back(dofs * dofs);
    }
    // Counting sort by colour keeps element order within a colour.
    const std::vector<int> colour = greedy_colours(term_elements, node_count);
    const int colours = colour.empty() ? 0 : 1 + *std::max_element(colour.begin(), colour.end());
    term.colour_offsets.assign(colours + 1, 0);
    for (const int c : colour) ++term.colour_offsets[c + 1];
    for (int c = 0; c < colours; ++c) term.colour_offsets[c + 1] += term.colour_offsets[c];
    term.by_colour.resize(colour.size());
    std::vector<int> next(term.colour_offsets.begin(), term.colour_offsets.end() - 1);
    for (std::size_t e = 0; e < colour.size(); ++e)
      term.by_colour[next[colour[e]]++] = static_cast<int>(e);
    terms_.push_back(std::move(term));
  }
  build_pattern(dof_count, fixed_dof, elements, pattern);
}

void HessianScatter::build_pattern(int dof_count, const std::vector<char>& fixed_dof,
                                   const std::vector<ElementNodes>& elements,
                                   SparseMatrix& pattern) {
  const int node_count = dof_count / 3;
  // Which elements each node belongs to: (global element, the node's place in it).
  struct Incidence {
    int term, element, place;
  };
  std::vector<int> incidence_offsets(node_count + 1, 0);
  for (const ElementNodes& term_elements : elements)
    for (const int node : term_elements.nodes) ++incidence_offsets[node + 1];
  for (int i = 0; i < node_count; ++i) incidence_offsets[i + 1] += incidence_offsets[i];
  std::vector<Incidence> incidence(incidence_offsets.back());
  {
    std::vector<int> next(incidence_offsets.begin(), incidence_offsets.end() - 1);
    for (std::size_t t = 0; t < elements.size(); ++t)
      for (std::size_t e = 0; e < elements[t].size(); ++e)
        for (int a = 0; a < elements[t].node_count(e); ++a)
          incidence[next[elements[t].begin(e)[a]]++] = {static_cast<int>(t), static_cast<int>(e),
                                                        a};
  }

  // Column 3j + c holds, for each node i ≥ j sharing an element with node j (ascending), the
  // rows 3i + r ≥ 3j + c of free dofs; a fixed dof's column, and an unused node's, only the
  // diagonal.
  std::vector<int> outer(dof_count + 1, 0), inner;
  std::vector<int> neighbours;
  std::vector<int> seen(node_count, -1);
  for (int j = 0; j < node_count; ++j) {
    neighbours.clear();
    for (int k = incidence_offsets[j]; k < incidence_offsets[j + 1]; ++k) {
      const ElementNodes& term_elements = elements[incidence[k].term];
      const int* nodes = term_elements.begin(incidence[k].element);
      for (int a = 0; a < term_elements.node_count(incidence[k].element); ++a)
        if (nodes[a] >= j && seen[nodes[a]] != j) {
          seen[nodes[a]] = j;
          neighbours.push_back(nodes[a]);
        }
    }
    std::sort(neighbours.begin(), neighbours.end());
    for (int c = 0; c < 3; ++c) {
      const int col = 3 * j + c;
      if (fixed_dof[col] || neighbours.empty()) {
        inner.push_back(col);
      } else {
        for (const int i : neighbours)
          for (int r = 0; r < 3; ++r)
            if (3 * i + r >= col && !fixed_dof[3 * i + r]) inner.push_back(3 * i + r);
      }
      outer[col + 1] = static_cast<int>(inner.size());
    }
  }
  pattern.resize(dof_count, dof_count);
  pattern.makeCompressed();
  pattern.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), pattern.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), pattern.innerIndexPtr());
  std::fill(pattern.valuePtr(), pattern.valuePtr() + inner.size(), 0.0);

  // Each block entry (row 3i + r, column 3j + c) with i ≥ j and both dofs free lands in
  // column 3j + c. First how many of each element's entries land, so that the second pass
  // writes them in place (a slot per block entry would take (3k)² ints per element, 7 MB at
  // 12k tets, to be scanned once).
  auto lands = [&](int row, int col) { return row >= col && !fixed_dof[row] && !fixed_dof[col]; };
  // A node pair (i > j) lands (free dofs of i) × (free dofs of j) entries; a node with itself
  // the lower triangle of its free dofs.
  std::vector<int> free_dofs(node_count);
  for (int i = 0; i < node_count; ++i)
    free_dofs[i] = 3 - fixed_dof[3 * i] - fixed_dof[3 * i + 1] - fixed_dof[3 * i + 2];
  entry_offsets_.assign(block_sizes_.size() + 1, 0);
  for (std::size_t t = 0; t < elements.size(); ++t)
    for (std::size_t e = 0; e < elements[t].size(); ++e) {
      const int* nodes = elements[t].begin(e);
      const int k = elements[t].node_count(e);
      int count = 0;
      for (int b = 0; b < k; ++b)
        for (int a = 0; a < k; ++a) {
          const int fa = free_dofs[nodes[a]], fb = free_dofs[nodes[b]];
          if (nodes[a] > nodes[b]) count += fa * fb;
          else if (nodes[a] == nodes[b]) count += fa * (fa + 1) / 2;
        }
      entry_offsets_[terms_[t].first_element + e + 1] = count;
    }
  for (std::size_t g = 0; g < block_sizes_.size(); ++g) entry_offsets_[g + 1] += entry_offsets_[g];
  entries_.resize(entry_offsets_.back());
  // Where in column 3j + c an entry goes is read from `place`, filled for node j's columns.
  std::vector<int> next(entry_offsets_.begin(), entry_offsets_.end() - 1);
  std::vector<int> place(3 * static_cast<std::size_t>(dof_count), -1);
  for (int j = 0; j < node_count; ++j) {
    for (int c = 0; c < 3; ++c)
      for (int k = outer[3 * j + c]; k < outer[3 * j + c + 1]; ++k) place[3 * inner[k] + c] = k;
    for (int k = incidence_offsets[j]; k < incidence_offsets[j + 1]; ++k) {
      const auto [t, e, b] = incidence[k];
      const ElementNodes& term_elements = elements[t];
      const int* nodes = term_elements.begin(e);
      const int dofs = 3 * term_elements.node_count(e);
      int& cursor = next[terms_[t].first_element + e];
      for (int a = 0; a < term_elements.node_count(e); ++a)
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) {
            const int row = 3 * nodes[a] + r, col = 3 * j + c;
            if (lands(row, col))
              entries_[cursor++] = {(3 * b + c) * dofs + 3 * a + r, place[3 * row + c]};
          }
    }
  }
  // The count above and this pass must agree, element by element.
  for (std::size_t g = 0; g < next.size(); ++g)
    if (next[g] != entry_offsets_[g + 1])
      throw std::logic_error("HessianScatter: counted and written entries differ");
  for (int d = 0; d < dof_count; ++d)
    if (fixed_dof[d]) fixed_diagonal_slots_.push_back(outer[d]);
}

void HessianScatter::add_blocks(std::size_t term_index, const ElementKernel& kernel,
                                double* values) const {
  const Term& term = terms_[term_index];
  for (std::size_t c = 0; c + 1 < term.colour_offsets.size(); ++c)
    tbb::parallel_for(tbb::blocked_range<int>(term.colour_offsets[c], term.colour_offsets[c + 1],
                                              kColourGrain),
                      [&](const tbb::blocked_range<int>& range) {
                        std::vector<double> block;
                        for (int k = range.begin(); k != range.end(); ++k) {
                          const int e = term.by_colour[k];
                          const int g = term.first_element + e;
                          const int size = block_sizes_[g];
                          block.assign(size, std::numeric_limits<double>::quiet_NaN());
                          kernel(e, block.data());
                          for (int i = entry_offsets_[g]; i < entry_offsets_[g + 1]; ++i)
                            values[entries_[i].slot] += block[entries_[i].entry];
                        }
                      });
}

}  // namespace shapectl
