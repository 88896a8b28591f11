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
      block_dofs_.push_back(3 * term_elements.node_count(e));
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
  // column 3j + c. Between two free nodes the block's rows land contiguously, in each of the
  // three columns: one start per column (a NodePair) says where. Entries touching a partly held
  // node are listed one by one (Entry); a fully held node's entries do not land at all.
  // First how many of each kind each element has, so that the second pass writes them in place.
  std::vector<int> free_dofs(node_count);
  for (int i = 0; i < node_count; ++i)
    free_dofs[i] = 3 - fixed_dof[3 * i] - fixed_dof[3 * i + 1] - fixed_dof[3 * i + 2];
  pair_offsets_.assign(block_dofs_.size() + 1, 0);
  entry_offsets_.assign(block_dofs_.size() + 1, 0);
  bool partly_held = false;
  for (std::size_t t = 0; t < elements.size(); ++t)
    for (std::size_t e = 0; e < elements[t].size(); ++e) {
      const int* nodes = elements[t].begin(e);
      const int k = elements[t].node_count(e), g = terms_[t].first_element + static_cast<int>(e);
      for (int b = 0; b < k; ++b)
        for (int a = 0; a < k; ++a) {
          if (nodes[a] < nodes[b]) continue;
          const int fa = free_dofs[nodes[a]], fb = free_dofs[nodes[b]];
          if (fa == 3 && fb == 3) ++pair_offsets_[g + 1];
          else entry_offsets_[g + 1] += nodes[a] == nodes[b] ? fa * (fa + 1) / 2 : fa * fb;
        }
      partly_held = partly_held || entry_offsets_[g + 1] > 0;
    }
  for (std::size_t g = 0; g < block_dofs_.size(); ++g) {
    pair_offsets_[g + 1] += pair_offsets_[g];
    entry_offsets_[g + 1] += entry_offsets_[g];
  }
  pairs_.reset(new NodePair[pair_offsets_.back()]);  // uninitialised: the pass below writes all
  entries_.reset(new Entry[entry_offsets_.back()]);
  std::vector<int> next_pair(pair_offsets_.begin(), pair_offsets_.end() - 1);
  std::vector<int> next_entry(entry_offsets_.begin(), entry_offsets_.end() - 1);
  // For node j's columns: where node i's first row sits in column 3j (free nodes), and where
  // each row sits in each column (`place`, only where some node is partly held).
  std::vector<int> first_row(node_count, -1);
  std::vector<int> place(partly_held ? 3 * static_cast<std::size_t>(dof_count) : 0, -1);
  auto lands = [&](int row, int col) { return row >= col && !fixed_dof[row] && !fixed_dof[col]; };
  for (int j = 0; j < node_count; ++j) {
    if (free_dofs[j] == 3)
      for (int k = outer[3 * j]; k < outer[3 * j + 1]; ++k)
        if (inner[k] % 3 == 0) first_row[inner[k] / 3] = k;
    if (partly_held)
      for (int c = 0; c < 3; ++c)
        for (int k = outer[3 * j + c]; k < outer[3 * j + c + 1]; ++k) place[3 * inner[k] + c] = k;
    for (int k = incidence_offsets[j]; k < incidence_offsets[j + 1]; ++k) {
      const auto [t, e, b] = incidence[k];
      const ElementNodes& term_elements = elements[t];
      const int* nodes = term_elements.begin(e);
      const int g = terms_[t].first_element + e;
      const int dofs = block_dofs_[g];
      for (int a = 0; a < term_elements.node_count(e); ++a) {
        const int i = nodes[a];
        if (i < j) continue;
        if (free_dofs[i] == 3 && free_dofs[j] == 3) {
          NodePair& pair = pairs_[next_pair[g]++];
          pair.block_column = (3 * b) * dofs + 3 * a;
          pair.diagonal = i == j;
          // Column 3j + c holds node j's rows from 3j + c, then node i's three rows.
          for (int c = 0; c < 3; ++c)
            pair.start[c] =
                (i == j ? outer[3 * j + c] : first_row[i] + outer[3 * j + c] - outer[3 * j]) - c;
          continue;
        }
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) {
            const int row = 3 * i + r, col = 3 * j + c;
            if (lands(row, col))
              entries_[next_entry[g]++] = {(3 * b + c) * dofs + 3 * a + r, place[3 * row + c]};
          }
      }
    }
  }
  // The count above and this pass must agree, element by element.
  for (std::size_t g = 0; g < next_pair.size(); ++g)
    if (next_pair[g] != pair_offsets_[g + 1] || next_entry[g] != entry_offsets_[g + 1])
      throw std::logic_error("HessianScatter: counted and written entries differ");
  for (int d = 0; d < dof_count; ++d)
    if (fixed_dof[d]) fixed_diagonal_slots_.push_back(outer[d]);
}

void HessianScatter::add_blocks(std::size_t term_index, const ElementKernel& kernel,
                                double* values) const {
  const Term& term = terms_[term_index];
  auto add_range = [&](int begin, int end) {
    std::vector<double> block;
    for (int k = begin; k != end; ++k) {
      const int e = term.by_colour[k];
      const int g = term.first_element + e;
      const int dofs = block_dofs_[g];
      block.assign(dofs * dofs, std::numeric_limits<double>::quiet_NaN());
      kernel(e, block.data());
      add_block(g, block.data(), values);
    }
  };
  // Colour by colour: the elements of one colour share no node, so no two threads add into
  // one value, and each value sums its blocks in the same order on every run.
  for (std::size_t c = 0; c + 1 < term.colour_offsets.size(); ++c) {
    const int begin = term.colour_offsets[c], end = term.colour_offsets[c + 1];
    tbb::parallel_for(tbb::blocked_range<int>(begin, end, kColourGrain),
                      [&](const tbb::blocked_range<int>& range) {
                        add_range(range.begin(), range.end());
                      });
  }
}

void HessianScatter::add_block(int g, const double* block, double* values) const {
  const int dofs = block_dofs_[g];
  for (int p = pair_offsets_[g]; p < pair_offsets_[g + 1]; ++p) {
    const NodePair& pair = pairs_[p];
    for (int c = 0; c < 3; ++c) {
      const double* column = block + pair.block_column + c * dofs;
      double* to = values + pair.start[c];
      for (int r = pair.diagonal ? c : 0; r < 3; ++r) to[r] += column[r];
    }
  }
  for (int i = entry_offsets_[g]; i < entry_offsets_[g + 1]; ++i)
    values[entries_[i].slot] += block[entries_[i].entry];
}

}  // namespace shapectl
