#include <shapectl/sim/hessian_assembler.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include <shapectl/fem/gravity.hpp>
#include <shapectl/fem/neo_hookean.hpp>
#include <shapectl/linalg/node_pattern.hpp>
#include <shapectl/sim/gripped_object.hpp>

#include "support/derivative_check.hpp"
#include "support/two_arm_scene.hpp"

namespace shapectl {
namespace {

// The bar of the two-arm scene, gripped at both ends, with the nodes of one face held fixed.
struct Problem {
  Scene scene = test::two_arm_scene({8, 2, 2});
  GrippedObject object{scene};
  NeoHookean elastic{object.mesh(), scene.material};
  Gravity gravity{object.mesh(), 40, Vec3(0, 0, -9.81)};
  std::vector<char> fixed_dof;
  Problem() {
    fixed_dof.assign(3 * object.node_count(), 0);
    for (int i = 0; i < object.node_count(); ++i)
      if (object.mesh().rest_positions()[i].y() > 0.0149)
        for (int d = 0; d < 3; ++d) fixed_dof[3 * i + d] = 1;
  }
  GripEnergy grip_at(const Eigen::VectorXd& joints) const {
    return GripEnergy(object.grips(), forward_kinematics(object.robot(), joints));
  }
  Positions deformed(std::mt19937& rng) const {
    return test::perturbed(object.reference_positions(), 0.001, rng);
  }
};

// The assembler's matrix the way it was made before the scatter map: all terms' triplets,
// lower triangle of free dofs, 1 on fixed diagonals.
SparseMatrix from_triplets(const std::vector<const EnergyTerm*>& terms, const Positions& x,
                           const std::vector<char>& fixed_dof, bool project_psd) {
  Triplets kept;
  for (const auto* term : terms)
    for (const auto& t : term->hessian_triplets(x, project_psd))
      if (t.row() >= t.col() && !fixed_dof[t.row()] && !fixed_dof[t.col()]) kept.push_back(t);
  for (int d = 0; d < static_cast<int>(fixed_dof.size()); ++d)
    if (fixed_dof[d]) kept.emplace_back(d, d, 1.0);
  SparseMatrix H(x.size(), x.size());
  H.setFromTriplets(kept.begin(), kept.end());
  H.makeCompressed();
  return H;
}

// Same pattern, and values within 8 ulps of the largest entry of their row: only the order of
// the sums differs.
void expect_same_matrix(const SparseMatrix& actual, const SparseMatrix& expected) {
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.nonZeros(), expected.nonZeros());
  for (int c = 0; c <= actual.cols(); ++c)
    ASSERT_EQ(actual.outerIndexPtr()[c], expected.outerIndexPtr()[c]) << "column " << c;
  const SparseMatrix full = expected.selfadjointView<Eigen::Lower>();
  const Eigen::MatrixXd dense(full);
  const Eigen::VectorXd row_max = dense.cwiseAbs().rowwise().maxCoeff();
  for (int k = 0; k < actual.nonZeros(); ++k) {
    const int row = actual.innerIndexPtr()[k];
    ASSERT_EQ(row, expected.innerIndexPtr()[k]);
    EXPECT_NEAR(actual.valuePtr()[k], expected.valuePtr()[k],
                8 * std::numeric_limits<double>::epsilon() * row_max[row])
        << "row " << row;
  }
}

TEST(HessianAssembler, EqualsTheTripletAssemblyWithFixedNodesAndGripSprings) {
  Problem p;
  std::mt19937 rng(7);
  const Positions x = p.deformed(rng);
  const GripEnergy grip = p.grip_at(p.object.reference_joints());
  ASSERT_FALSE(p.object.grips().nodes().empty());
  const std::vector<const EnergyTerm*> terms{&p.elastic, &p.gravity, &grip};
  HessianAssembler assembler(x.size(), p.fixed_dof);
  for (const bool projected : {false, true}) {
    SCOPED_TRACE(projected ? "projected" : "true Hessian");
    expect_same_matrix(assembler.assemble(terms, x, projected),
                       from_triplets(terms, x, p.fixed_dof, projected));
  }
  // The fixed dofs really were eliminated: their column holds only the diagonal 1.
  int fixed = 0;
  for (int d = 0; d < x.size(); ++d)
    if (p.fixed_dof[d]) {
      ++fixed;
      EXPECT_EQ(assembler.matrix().col(d).nonZeros(), 1);
      EXPECT_EQ(assembler.matrix().coeff(d, d), 1.0);
    }
  EXPECT_GT(fixed, 0);
}

TEST(HessianAssembler, KeepsItsPatternForTheSameElementsAndRebuildsItForNewOnes) {
  Problem p;
  std::mt19937 rng(3);
  const Positions x = p.deformed(rng);
  const GripEnergy at_reference = p.grip_at(p.object.reference_joints());
  HessianAssembler assembler(x.size(), p.fixed_dof);
  EXPECT_EQ(assembler.pattern_version(), 0);
  assembler.assemble({&p.elastic, &at_reference}, x, false);
  EXPECT_EQ(assembler.pattern_version(), 1);

  // Other joints, other positions: the same elements, so the same pattern, values of x2.
  Eigen::VectorXd joints = p.object.reference_joints();
  joints[1] += 0.1;
  const GripEnergy moved = p.grip_at(joints);
  const Positions x2 = p.deformed(rng);
  const SparseMatrix& H = assembler.assemble({&p.elastic, &moved}, x2, false);
  EXPECT_EQ(assembler.pattern_version(), 1);
  expect_same_matrix(H, from_triplets({&p.elastic, &moved}, x2, p.fixed_dof, false));

  // Without the grip springs the elements differ: a new pattern, and no grip stiffness in it.
  const SparseMatrix& elastic_only = assembler.assemble({&p.elastic}, x2, false);
  EXPECT_EQ(assembler.pattern_version(), 2);
  expect_same_matrix(elastic_only, from_triplets({&p.elastic}, x2, p.fixed_dof, false));
}

TEST(HessianAssembler, AssemblesTheValuesOfTheLearnedPatternAndNothingBeforeIt) {
  Problem p;
  std::mt19937 rng(5);
  const Positions x = p.deformed(rng);
  const GripEnergy grip = p.grip_at(p.object.reference_joints());
  const std::vector<const EnergyTerm*> terms{&p.elastic, &p.gravity, &grip};
  HessianAssembler assembler(x.size(), p.fixed_dof);
  EXPECT_THROW(assembler.assemble_values(terms, x, false), std::logic_error);
  EXPECT_EQ(assembler.learn_pattern(terms, x), 1);
  expect_same_matrix(assembler.assemble_values(terms, x, false),
                     from_triplets(terms, x, p.fixed_dof, false));
  EXPECT_THROW(assembler.assemble_values({&p.elastic}, x, false), std::logic_error)
      << "terms other than the learned ones";
}

TEST(HessianAssembler, ItsNodePatternIsTheMatrixsWithHeldAndPartlyHeldNodes) {
  Problem p;
  int partly = 0;
  for (int i = 0; i < p.object.node_count(); i += 7)
    if (!p.fixed_dof[3 * i]) {
      p.fixed_dof[3 * i + 1 + i % 2] = 1;  // y or z held
      ++partly;
    }
  ASSERT_GT(partly, 3);
  std::mt19937 rng(5);
  const Positions x = p.deformed(rng);
  const GripEnergy grip = p.grip_at(p.object.reference_joints());
  HessianAssembler assembler(x.size(), p.fixed_dof);
  const SparseMatrix& H = assembler.assemble({&p.elastic, &p.gravity, &grip}, x, false);
  expect_same_matrix(H, from_triplets({&p.elastic, &p.gravity, &grip}, x, p.fixed_dof, false));
  const std::optional<SparseMatrix> expected = node_pattern(H);
  ASSERT_TRUE(expected);
  const SparseMatrix& nodes = assembler.node_pattern();
  ASSERT_EQ(nodes.rows(), expected->rows());
  ASSERT_EQ(nodes.nonZeros(), expected->nonZeros());
  EXPECT_TRUE(std::equal(nodes.outerIndexPtr(), nodes.outerIndexPtr() + nodes.cols() + 1,
                         expected->outerIndexPtr()));
  EXPECT_TRUE(std::equal(nodes.innerIndexPtr(), nodes.innerIndexPtr() + nodes.nonZeros(),
                         expected->innerIndexPtr()));
}

TEST(HessianAssembler, AnInvertedTetLeavesNonFiniteValues) {
  Problem p;
  Positions x = p.object.reference_positions();
  const TetRest& tet = p.object.mesh().tets()[0];
  // Swap two corners: the tet turns inside out.
  const Vec3 corner = x.segment<3>(3 * tet.nodes[0]);
  x.segment<3>(3 * tet.nodes[0]) = x.segment<3>(3 * tet.nodes[1]);
  x.segment<3>(3 * tet.nodes[1]) = corner;
  const std::vector<char> free(x.size(), 0);
  HessianAssembler assembler(x.size(), free);
  const SparseMatrix& H = assembler.assemble({&p.elastic}, x, false);
  EXPECT_FALSE(Eigen::Map<const Eigen::VectorXd>(H.valuePtr(), H.nonZeros()).allFinite());
}

}  // namespace
}  // namespace shapectl
