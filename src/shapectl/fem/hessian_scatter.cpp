#include <shapectl/fem/hessian_scatter.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <shapectl/hand_off.hpp>

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
constexpr int kPatternNodeGrain = 256;

// Runs f(begin, end) over ranges of [0, node_count) on all cores.
template <typename F>
void for_node_ranges(int node_count, F&& f) {
  HandOff hand_off;
  tbb::parallel_for(tbb::blocked_range<int>(0, node_count, kPatternNodeGrain),
                    hand_off([&](const tbb::blocked_range<int>& range) {
                      f(range.begin(), range.end());
                    }));
  hand_off.joined();
}

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
  // Which elements each node belongs to: (term, element, the node's place in it).
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
  std::vector<int> free_dofs(node_count);
  for (int i = 0; i < node_count; ++i)
    free_dofs[i] = 3 - fixed_dof[3 * i] - fixed_dof[3 * i + 1] - fixed_dof[3 * i + 2];

  // Node j's neighbours: the nodes i ≥ j it shares an element with, ascending. Counted, then
  // written in place, node by node on all cores; `seen` (one per thread) dedupes.
  tbb::enumerable_thread_specific<std::vector<int>> seen_by_thread(node_count, -1);
  auto for_each_neighbour = [&](int j, std::vector<int>& seen, auto&& visit) {
    for (int k = incidence_offsets[j]; k < incidence_offsets[j + 1]; ++k) {
      const ElementNodes& term_elements = elements[incidence[k].term];
      const int* nodes = term_elements.begin(incidence[k].element);
      for (int a = 0; a < term_elements.node_count(incidence[k].element); ++a)
        if (nodes[a] >= j && seen[nodes[a]] != j) {
          seen[nodes[a]] = j;
          visit(nodes[a]);
        }
    }
  };
  std::vector<int> neighbour_offsets(node_count + 1, 0);
  for_node_ranges(node_count, [&](int begin, int end) {
    std::vector<int>& seen = seen_by_thread.local();
    for (int j = begin; j < end; ++j)
      for_each_neighbour(j, seen, [&](int) { ++neighbour_offsets[j + 1]; });
  });
  for (int j = 0; j < node_count; ++j) neighbour_offsets[j + 1] += neighbour_offsets[j];
  std::vector<int> neighbours(neighbour_offsets.back());
  for (auto& seen : seen_by_thread) std::fill(seen.begin(), seen.end(), -1);
  for_node_ranges(node_count, [&](int begin, int end) {
    std::vector<int>& seen = seen_by_thread.local();
    for (int j = begin; j < end; ++j) {
      int* next = neighbours.data() + neighbour_offsets[j];
      for_each_neighbour(j, seen, [&](int i) { *next++ = i; });
      std::sort(neighbours.data() + neighbour_offsets[j], next);
    }
  });

  // Column 3j + c holds, for each neighbour i of node j, the rows 3i + r ≥ 3j + c of free dofs;
  // a fixed dof's column, and an unused node's, only the diagonal.
  auto column_rows = [&](int col, auto&& visit) {
    const int j = col / 3;
    if (fixed_dof[col] || neighbour_offsets[j] == neighbour_offsets[j + 1]) return visit(col);
    for (int k = neighbour_offsets[j]; k < neighbour_offsets[j + 1]; ++k)
      for (int row = std::max(3 * neighbours[k], col); row < 3 * neighbours[k] + 3; ++row)
        if (!fixed_dof[row]) visit(row);
  };
  pattern.resize(dof_count, dof_count);
  pattern.makeCompressed();
  int* outer = pattern.outerIndexPtr();
  outer[0] = 0;
  for_node_ranges(node_count, [&](int begin, int end) {
    for (int col = 3 * begin; col < 3 * end; ++col) {
      int rows = 0;
      column_rows(col, [&](int) { ++rows; });
      outer[col + 1] = rows;
    }
  });
  for (int col = 0; col < dof_count; ++col) outer[col + 1] += outer[col];
  pattern.resizeNonZeros(outer[dof_count]);
  int* inner = pattern.innerIndexPtr();
  double* values = pattern.valuePtr();
  for_node_ranges(node_count, [&](int begin, int end) {
    for (int col = 3 * begin; col < 3 * end; ++col) {
      int* next = inner + outer[col];
      column_rows(col, [&](int row) { *next++ = row; });
      std::fill(values + outer[col], values + outer[col + 1], 0.0);
    }
  });
  // Where row `row` sits in column `col` (both kept).
  auto slot = [&](int row, int col) {
    return static_cast<int>(std::lower_bound(inner + outer[col], inner + outer[col + 1], row) -
                            inner);
  };

  // Each block entry (row 3i + r, column 3j + c) with i ≥ j and both dofs free lands in
  // column 3j + c. Between two free nodes the block's rows land contiguously in each of the
  // three columns (a NodePair). Entries touching a partly held node are listed one by one
  // (Entry); a fully held node's entries do not land at all. An element lists them by its
  // node places b, then a. First how many each place has, so that the pass below, node by
  // node, writes each place's where they go.
  const int element_count = static_cast<int>(block_dofs_.size());
  pair_offsets_.assign(element_count + 1, 0);
  entry_offsets_.assign(element_count + 1, 0);
  struct Landings {
    int pairs, entries;  // where the place's first pair and entry go
  };
  std::vector<std::vector<Landings>> place_landings(elements.size());
  Landings next{0, 0};
  for (std::size_t t = 0; t < elements.size(); ++t) {
    place_landings[t].resize(elements[t].nodes.size());
    for (std::size_t e = 0; e < elements[t].size(); ++e) {
      const int* nodes = elements[t].begin(e);
      const int k = elements[t].node_count(e);
      for (int b = 0; b < k; ++b) {
        place_landings[t][elements[t].offsets[e] + b] = next;
        for (int a = 0; a < k; ++a) {
          const int i = nodes[a], j = nodes[b];
          if (i < j) continue;
          const int fi = free_dofs[i], fj = free_dofs[j];
          if (fi == 3 && fj == 3) ++next.pairs;
          else next.entries += i == j ? fi * (fi + 1) / 2 : fi * fj;
        }
      }
      const int g = terms_[t].first_element + static_cast<int>(e);
      pair_offsets_[g + 1] = next.pairs;
      entry_offsets_[g + 1] = next.entries;
    }
  }
  pairs_.reset(new NodePair[next.pairs]);  // uninitialised: the pass below writes all
  entries_.reset(new Entry[next.entries]);
  // Node by node on all cores, each node j writing the landings of its places in elements.
  tbb::enumerable_thread_specific<std::vector<int>> first_row_by_thread(node_count, -1);
  for_node_ranges(node_count, [&](int begin, int end) {
    std::vector<int>& first_row = first_row_by_thread.local();  // node i's first row in 3j
    for (int j = begin; j < end; ++j) {
      if (free_dofs[j] == 3)
        for (int k = outer[3 * j]; k < outer[3 * j + 1]; ++k)
          if (inner[k] % 3 == 0) first_row[inner[k] / 3] = k;
      for (int n = incidence_offsets[j]; n < incidence_offsets[j + 1]; ++n) {
        const auto [t, e, b] = incidence[n];
        const int* nodes = elements[t].begin(e);
        const int k = elements[t].node_count(e), g = terms_[t].first_element + e;
        const int dofs = block_dofs_[g];
        const Landings first = place_landings[t][elements[t].offsets[e] + b];
        NodePair* pair = pairs_.get() + first.pairs;
        Entry* entry = entries_.get() + first.entries;
        for (int a = 0; a < k; ++a) {
          const int i = nodes[a];
          if (i < j) continue;
          if (free_dofs[i] == 3 && free_dofs[j] == 3) {
            *pair++ = {(3 * b) * dofs + 3 * a, first_row[i], outer[3 * j + 1] - outer[3 * j],
                       i == j};
            continue;
          }
          for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) {
              const int row = 3 * i + r, col = 3 * j + c;
              if (row >= col && !fixed_dof[row] && !fixed_dof[col])
                *entry++ = {(3 * b + c) * dofs + 3 * a + r, slot(row, col)};
            }
        }
        // This place's landings must end where the next place's begin.
        const Landings last = b + 1 < k ? place_landings[t][elements[t].offsets[e] + b + 1]
                                        : Landings{pair_offsets_[g + 1], entry_offsets_[g + 1]};
        if (pair != pairs_.get() + last.pairs || entry != entries_.get() + last.entries)
          throw std::logic_error("HessianScatter: counted and written entries differ");
      }
    }
  });
  for (int d = 0; d < dof_count; ++d)
    if (fixed_dof[d]) fixed_diagonal_slots_.push_back(outer[d]);

  // The node pattern: node pairs with an entry, i.e. both with a free dof.
  node_pattern_.resize(node_count, node_count);
  node_pattern_.makeCompressed();
  int* node_outer = node_pattern_.outerIndexPtr();
  node_outer[0] = 0;
  std::vector<int> node_inner;
  node_inner.reserve(neighbours.size() + node_count);
  for (int j = 0; j < node_count; ++j) {
    node_inner.push_back(j);
    if (free_dofs[j] > 0)
      for (int k = neighbour_offsets[j]; k < neighbour_offsets[j + 1]; ++k)
        if (neighbours[k] > j && free_dofs[neighbours[k]] > 0) node_inner.push_back(neighbours[k]);
    node_outer[j + 1] = static_cast<int>(node_inner.size());
  }
  node_pattern_.resizeNonZeros(static_cast<Eigen::Index>(node_inner.size()));
  std::copy(node_inner.begin(), node_inner.end(), node_pattern_.innerIndexPtr());
  std::fill_n(node_pattern_.valuePtr(), node_inner.size(), 0.0);
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
    HandOff hand_off;
    tbb::parallel_for(tbb::blocked_range<int>(begin, end, kColourGrain),
                      hand_off([&](const tbb::blocked_range<int>& range) {
                        add_range(range.begin(), range.end());
                      }));
    hand_off.joined();
  }
}

void HessianScatter::add_block(int g, const double* block, double* values) const {
  const int dofs = block_dofs_[g];
  for (int p = pair_offsets_[g]; p < pair_offsets_[g + 1]; ++p) {
    const NodePair& pair = pairs_[p];
    for (int c = 0; c < 3; ++c) {
      const double* column = block + pair.block_column + c * dofs;
      double* to = values + pair.start + c * pair.column_length - c * (c + 1) / 2;
      for (int r = pair.diagonal ? c : 0; r < 3; ++r) to[r] += column[r];
    }
  }
  for (int i = entry_offsets_[g]; i < entry_offsets_[g + 1]; ++i)
    values[entries_[i].slot] += block[entries_[i].entry];
}

}  // namespace shapectl
