#include <shapectl/fem/energy_term.hpp>

#include <limits>

namespace shapectl {

namespace {

// Runs the kernels one after another and appends each block's entries as triplets.
class TripletSink : public ElementHessianSink {
 public:
  TripletSink(const ElementNodes& elements, Triplets& out) : elements_(elements), out_(out) {}
  void add_blocks(const ElementKernel& kernel) override {
    std::vector<double> block;
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const int dofs = 3 * elements_.node_count(e);
      block.assign(dofs * dofs, std::numeric_limits<double>::quiet_NaN());
      kernel(e, block.data());
      const int* nodes = elements_.begin(e);
      for (int c = 0; c < dofs; ++c)
        for (int r = 0; r < dofs; ++r)
          out_.emplace_back(3 * nodes[r / 3] + r % 3, 3 * nodes[c / 3] + c % 3,
                            block[c * dofs + r]);
    }
  }

 private:
  const ElementNodes& elements_;
  Triplets& out_;
};

}  // namespace

double EnergyTerm::value_and_add_gradient(const Positions& x, Eigen::VectorXd& gradient) const {
  add_gradient(x, gradient);
  return value(x);
}

Triplets EnergyTerm::hessian_triplets(const Positions& x, bool project_psd) const {
  ElementNodes elements;
  hessian_elements(x, elements);
  Triplets out;
  TripletSink sink(elements, out);
  add_hessian(x, sink, project_psd);
  return out;
}

}  // namespace shapectl
