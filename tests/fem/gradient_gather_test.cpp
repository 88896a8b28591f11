#include <shapectl/fem/gradient_gather.hpp>

#include <gtest/gtest.h>

#include <random>
#include <tbb/task_arena.h>

namespace shapectl {
namespace {

// Elements of 1, 2 and 4 nodes (a grip, a spring, a tet) over `node_count` nodes, seeded.
ElementNodes mixed_elements(int node_count, int element_count, std::mt19937& rng) {
  std::uniform_int_distribution<int> node(0, node_count - 1);
  ElementNodes elements;
  for (int e = 0; e < element_count; ++e) {
    switch (e % 3) {
      case 0: elements.add({node(rng)}); break;
      case 1: elements.add({node(rng), node(rng)}); break;
      default: elements.add({node(rng), node(rng), node(rng), node(rng)}); break;
    }
  }
  return elements;
}

// Values of very different magnitudes, so that the order of summation shows in the last bits.
std::vector<double> corner_values(std::size_t count, std::mt19937& rng) {
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-20, 20);
  std::vector<double> v(count);
  for (double& value : v) value = std::ldexp(mantissa(rng), exponent(rng));
  return v;
}

TEST(GradientGather, AddsWhatTheSerialScatterAddsBitForBitOnAnyThreadCount) {
  std::mt19937 rng(3);
  const int node_count = 700;  // several grains of nodes
  const ElementNodes elements = mixed_elements(node_count, 3000, rng);
  const std::vector<double> corners = corner_values(3 * elements.nodes.size(), rng);
  Eigen::VectorXd start(3 * node_count);
  for (int i = 0; i < start.size(); ++i) start[i] = std::ldexp(1.0 + i, -10);

  // The reference: element by element, in order, onto `start`.
  Eigen::VectorXd serial = start;
  for (std::size_t k = 0; k < elements.nodes.size(); ++k)
    serial.segment<3>(3 * elements.nodes[k]) += Eigen::Map<const Vec3>(&corners[3 * k]);
  // The same sums in reverse order differ: the comparison below can see an order change.
  Eigen::VectorXd reversed = start;
  for (std::size_t k = elements.nodes.size(); k-- > 0;)
    reversed.segment<3>(3 * elements.nodes[k]) += Eigen::Map<const Vec3>(&corners[3 * k]);
  ASSERT_FALSE((reversed.array() == serial.array()).all());

  const GradientGather gather(elements, node_count);
  for (const int threads : {1, 2, 4}) {
    Eigen::VectorXd gathered = start;
    tbb::task_arena(threads).execute([&] { gather.add(corners.data(), gathered); });
    EXPECT_TRUE((gathered.array() == serial.array()).all())
        << threads << " threads: differs by up to " << (gathered - serial).cwiseAbs().maxCoeff();
  }
}

TEST(GradientGather, LeavesNodesOfNoElementUntouched) {
  ElementNodes elements;
  elements.add({0, 2});
  const GradientGather gather(elements, 4);
  const std::vector<double> corners = {1, 2, 3, 4, 5, 6};
  Eigen::VectorXd g = Eigen::VectorXd::Constant(12, 0.5);
  gather.add(corners.data(), g);
  Eigen::VectorXd expected = Eigen::VectorXd::Constant(12, 0.5);
  expected.segment<3>(0) += Vec3(1, 2, 3);
  expected.segment<3>(6) += Vec3(4, 5, 6);
  EXPECT_EQ(g, expected);
}

}  // namespace
}  // namespace shapectl
