// Contact benchmarks (issue 34): a 1 m cable (2,008 surface vertices) resting at d̂/2 on a
// plane, on a box and on a closed plate mesh of 10,160 triangles; value, gradient, Hessian
// blocks and the CCD step bound, as the statics' line search and Newton steps call them.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/mesh/box_mesh.hpp>

namespace shapectl {
namespace {

constexpr double kDhat = 1e-3;

const TetMesh& cable() {
  static const TetMesh mesh = make_box_mesh({1.0, 0.01, 0.01}, {250, 2, 2});
  return mesh;
}

// The obstacle under the cable, its top d̂/2 below the cable's bottom.
std::vector<Obstacle> table(int kind) {
  const double top = -0.005 - 0.5 * kDhat;
  if (kind == 0) return {make_plane("table", Vec3(0, 0, top), Vec3::UnitZ())};
  if (kind == 1)
    return {make_box("table", Vec3(1.2, 0.2, 0.02),
                     Eigen::Isometry3d(Eigen::Translation3d(0, 0, top - 0.01)))};
  const TetMesh plate = make_box_mesh({1.2, 0.2, 0.02}, {120, 20, 1});
  std::vector<Vec3> v = plate.rest_positions();
  for (Vec3& p : v) p.z() += top - 0.01;
  return {make_mesh_obstacle("plate", v, plate.surface_triangles())};
}

// Runs every element's kernel into one reused block.
class DiscardingSink : public ElementHessianSink {
 public:
  explicit DiscardingSink(std::size_t elements) : elements_(elements) {}
  void add_blocks(const ElementKernel& kernel) override {
    for (std::size_t e = 0; e < elements_; ++e) kernel(e, block_);
    benchmark::DoNotOptimize(block_);
  }

 private:
  std::size_t elements_;
  double block_[81];
};

void run(benchmark::State& state, int what) {
  const ObstacleContact contact(cable(), table(static_cast<int>(state.range(0))), kDhat, 10.0);
  const Positions x = cable().rest_vector();
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  const Eigen::VectorXd dx = Eigen::VectorXd::Constant(x.size(), -0.001);
  ElementNodes elements;
  contact.hessian_elements(x, elements);
  DiscardingSink sink(elements.size());
  for (auto _ : state) {
    if (what == 0) benchmark::DoNotOptimize(contact.value(x));
    if (what == 1) contact.add_gradient(x, g);
    if (what == 2) contact.add_hessian(x, sink, false);
    if (what == 3) benchmark::DoNotOptimize(contact.max_step(x, dx));
  }
  state.counters["contacts"] = contact.summary(x).count;
}

void BM_ContactValue(benchmark::State& state) { run(state, 0); }
void BM_ContactGradient(benchmark::State& state) { run(state, 1); }
void BM_ContactHessian(benchmark::State& state) { run(state, 2); }
void BM_ContactMaxStep(benchmark::State& state) { run(state, 3); }
// Argument: 0 plane, 1 box, 2 plate mesh.
BENCHMARK(BM_ContactValue)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ContactGradient)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ContactHessian)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ContactMaxStep)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace shapectl

BENCHMARK_MAIN();
