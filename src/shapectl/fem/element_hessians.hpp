#pragma once
// How an energy term hands its Hessian to an assembler: as dense blocks, one per element (a
// tet, a spring), each coupling every degree of freedom of the element's nodes. The assembler
// learns the elements' nodes once, then adds each block straight into the compressed matrix.
#include <cstddef>
#include <functional>
#include <initializer_list>
#include <vector>

namespace shapectl {

// The nodes of each element, in a term's fixed element order: element e has the nodes
// nodes[offsets[e]] … nodes[offsets[e + 1] − 1].
struct ElementNodes {
  std::vector<int> offsets{0};
  std::vector<int> nodes;

  void add(std::initializer_list<int> element_nodes) {
    nodes.insert(nodes.end(), element_nodes);
    offsets.push_back(static_cast<int>(nodes.size()));
  }
  void clear() {
    offsets.assign(1, 0);
    nodes.clear();
  }
  std::size_t size() const { return offsets.size() - 1; }
  int node_count(std::size_t e) const { return offsets[e + 1] - offsets[e]; }
  const int* begin(std::size_t e) const { return nodes.data() + offsets[e]; }
  bool operator==(const ElementNodes& o) const { return offsets == o.offsets && nodes == o.nodes; }
};

// Fills `block` with element e's Hessian: (3k × 3k), column-major, k the element's node count,
// dofs ordered node by node as in ElementNodes (x, y, z each). Entries it leaves unwritten are
// NaN (a kernel that cannot evaluate, e.g. an inverted tet, poisons the matrix).
using ElementKernel = std::function<void(std::size_t element, double* block)>;

class ElementHessianSink {
 public:
  virtual ~ElementHessianSink() = default;
  // Runs `kernel` for every element of the term (possibly several at once on different
  // threads) and adds each block to the Hessian.
  virtual void add_blocks(const ElementKernel& kernel) = 0;
};

}  // namespace shapectl
