#include <shapectl/linalg/node_pattern.hpp>

#include <algorithm>

namespace shapectl {

std::optional<SparseMatrix> node_pattern(const SparseMatrix& lower) {
  const Eigen::Index dofs = lower.rows();
  if (dofs != lower.cols() || dofs % 3 != 0 || !lower.isCompressed()) return std::nullopt;
  const int nodes = static_cast<int>(dofs / 3);
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  // Dofs with an entry off the diagonal, in their row or their column.
  std::vector<char> coupled(dofs, 0);
  for (int col = 0; col < dofs; ++col)
    for (int k = outer[col]; k < outer[col + 1]; ++k)
      if (inner[k] != col) {
        if (inner[k] < col) return std::nullopt;  // not the lower triangle
        coupled[inner[k]] = coupled[col] = 1;
      }
  // Node pairs (i ≥ j) with an entry, column by column; `mark` dedupes within a node column.
  std::vector<int> node_outer(nodes + 1, 0), node_inner;
  node_inner.reserve(lower.nonZeros() / 9 + nodes);
  std::vector<int> mark(nodes, -1);
  for (int j = 0; j < nodes; ++j) {
    const auto first = node_inner.size();
    mark[j] = j;
    node_inner.push_back(j);
    for (int col = 3 * j; col < 3 * j + 3; ++col)
      for (int k = outer[col]; k < outer[col + 1]; ++k)
        if (const int i = inner[k] / 3; mark[i] != j) {
          mark[i] = j;
          node_inner.push_back(i);
        }
    std::sort(node_inner.begin() + first, node_inner.end());
    node_outer[j + 1] = static_cast<int>(node_inner.size());
  }
  // `lower` is in node blocks iff it has as many entries as the blocks of its node pattern:
  // every entry lies in one (by construction), so equal counts mean the same set.
  Eigen::Index expected = 0;
  for (int j = 0; j < nodes; ++j)
    for (int col = 3 * j; col < 3 * j + 3; ++col) {
      if (!coupled[col]) {
        ++expected;  // the diagonal alone
        continue;
      }
      for (int k = node_outer[j]; k < node_outer[j + 1]; ++k)
        for (int row = 3 * node_inner[k]; row < 3 * node_inner[k] + 3; ++row)
          expected += row >= col && (coupled[row] || row == col);
    }
  // An uncoupled dof's entries must be its diagonal alone: already so, since any other entry
  // would have marked it coupled. A coupled column without its diagonal shows in the count.
  if (expected != lower.nonZeros()) return std::nullopt;
  SparseMatrix pattern(nodes, nodes);
  pattern.resizeNonZeros(static_cast<Eigen::Index>(node_inner.size()));
  std::copy(node_outer.begin(), node_outer.end(), pattern.outerIndexPtr());
  std::copy(node_inner.begin(), node_inner.end(), pattern.innerIndexPtr());
  std::fill(pattern.valuePtr(), pattern.valuePtr() + node_inner.size(), 0.0);
  return pattern;
}

std::vector<int> dof_order(const std::vector<int>& node_order) {
  std::vector<int> order(3 * node_order.size());
  for (std::size_t k = 0; k < node_order.size(); ++k)
    for (int c = 0; c < 3; ++c) order[3 * k + c] = 3 * node_order[k] + c;
  return order;
}

}  // namespace shapectl
