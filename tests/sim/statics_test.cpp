#include <shapectl/sim/object_statics.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include <shapectl/mesh/box_mesh.hpp>

#include "support/linear_solvers.hpp"

namespace shapectl {
namespace {

Scene bar_scene(const std::array<int, 3>& cells, const Material& material, double clamp_depth,
                bool clamp_both_ends) {
  Scene s;
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({0.32, 0.03, 0.03}, cells));
  s.material = material;
  NodeSelection fixed;
  fixed.box = AlignedBox{Vec3(-1, -1, -1), Vec3(-0.16 + clamp_depth, 1, 1)};
  s.fixed = fixed;
  if (clamp_both_ends) {
    for (int i = 0; i < s.object_mesh->node_count(); ++i)
      if (s.object_mesh->rest_positions()[i].x() > 0.16 - clamp_depth) s.fixed->nodes.push_back(i);
  }
  return s;
}

// The statics tests that every linear solver must pass alike (support/linear_solvers.hpp); those
// that count Krylov or chord steps against a cheap solve's rule stay with the automatic choice.
class StaticsEachSolver : public test::EachLinearSolver {};

TEST_P(StaticsEachSolver, ClampedBarConvergesSuperlinearly) {
  // A soft foam bar clamped at both ends sags visibly under its own weight.
  const Scene scene =
      with_solver(bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true));
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r =
      statics.solve(x);  // from scratch: Newton proper, a factorization every step
  ASSERT_TRUE(r.converged()) << r.reason;
  EXPECT_LE(r.iterations, 12);
  ASSERT_GE(r.log.size(), 3u);
  // The middle sags by millimetres: a nonlinear, not a trivial, solve.
  double sag = 0;
  for (int i = 0; i < statics.mesh().node_count(); ++i)
    sag = std::min(sag, x[3 * i + 2] - scene.world_rest_positions()[3 * i + 2]);
  EXPECT_LT(sag, -0.002);
  // Superlinear: the ratio of successive residuals keeps shrinking over the last steps,
  // down to far below what linear convergence would give.
  std::vector<double> residuals;
  for (const auto& it : r.log) residuals.push_back(it.residual);
  residuals.push_back(r.residual);
  const std::size_t n = residuals.size();
  const double ratio_last = residuals[n - 1] / residuals[n - 2];
  const double ratio_before = residuals[n - 2] / residuals[n - 3];
  EXPECT_LT(ratio_last, ratio_before);
  EXPECT_LT(ratio_last, 1e-2);
  // The final steps use the true Hessian.
  EXPECT_FALSE(r.log.back().projected);
}

TEST_P(StaticsEachSolver, ChordStepsSaveFactorizationsAndReachTheSameEquilibrium) {
  const Scene scene =
      with_solver(bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true));
  Positions newton_x = scene.world_rest_positions(), chord_x = newton_x;
  const ObjectStatics statics(scene);
  const ObjectStatics& chord = statics;
  StaticsWorkspace newton_ws = statics.make_workspace(), chord_ws = statics.make_workspace();
  ASSERT_TRUE(statics.solve(newton_ws, newton_x).converged());
  ASSERT_TRUE(statics.solve(chord_ws, chord_x).converged());
  // Warm re-solves after the +x clamp moves 2 mm sideways: the case chord steps are for.
  for (int i = 0; i < chord.mesh().node_count(); ++i)
    if (chord.fixed_node()[i] && chord.mesh().rest_positions()[i].x() > 0) {
      newton_x[3 * i + 1] += 2e-3;
      chord_x[3 * i + 1] += 2e-3;
    }
  // Newton proper forgets the earlier factorization; chord steps start with it.
  newton_ws.forget_factor();
  const StaticsResult rn = statics.solve(newton_ws, newton_x);
  const StaticsResult rc = statics.solve(chord_ws, chord_x, nullptr, 0, &chord_ws);
  ASSERT_TRUE(rn.converged()) << rn.reason;
  ASSERT_TRUE(rc.converged()) << rc.reason;
  EXPECT_LT(rc.factorizations, rn.factorizations);
  int chord_steps = 0;
  for (const auto& it : rc.log) chord_steps += it.chord;
  EXPECT_GT(chord_steps, 0);
  // Same equilibrium: both stop at forces below 1e-6 N, a sub-micrometre difference.
  double largest = 0;
  for (int i = 0; i < chord.mesh().node_count(); ++i)
    largest = std::max(largest, (chord_x - newton_x).segment<3>(3 * i).norm());
  EXPECT_LT(largest, 1e-6);
}

// Moves the nodes of the +x clamp sideways (y) by `dy` metres.
void move_right_clamp(const ObjectStatics& statics, Positions& x, double dy) {
  for (int i = 0; i < statics.mesh().node_count(); ++i)
    if (statics.fixed_node()[i] && statics.mesh().rest_positions()[i].x() > 0) x[3 * i + 1] += dy;
}

// The bar clamped at both ends, at its equilibrium, with chord steps off: a warm solve's steps
// without a new factorization are then all Krylov ones (conjugate gradients preconditioned with
// the equilibrium's factorization, which `ws` holds).
// Solves `scene` from rest, moves its right clamp by dy and re-solves warm (the first solve's
// factor as the chord): that solve's result; x its equilibrium.
StaticsResult warm_resolve(const Scene& scene, double dy, Positions& x) {
  const ObjectStatics statics(scene);
  StaticsWorkspace ws = statics.make_workspace();
  x = scene.world_rest_positions();
  EXPECT_TRUE(statics.solve(ws, x).converged());
  move_right_clamp(statics, x, dy);
  return statics.solve(ws, x, nullptr, 0, &ws);
}

struct KrylovBar {
  ObjectStatics statics{krylov_scene()};
  StaticsWorkspace ws = statics.make_workspace();
  Positions x = statics_equilibrium();

  static Scene krylov_scene() {
    Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true);
    scene.statics.chord_steps = false;
    return scene;
  }
  Positions statics_equilibrium() {
    Positions rest = krylov_scene().world_rest_positions();
    EXPECT_TRUE(statics.solve(ws, rest).converged());
    return rest;
  }
};

// A solve with Krylov steps (`krylov`, ending at `krylov_x`) against exact Newton on the same
// problem: it took Krylov steps, fewer factorizations, and converged on the true residual to
// the same equilibrium (to a sub-micrometre). Returns its Krylov steps.
int expect_krylov_steps_save_factorizations(const ObjectStatics& statics,
                                            const StaticsResult& krylov, const Positions& krylov_x,
                                            const StaticsResult& newton,
                                            const Positions& newton_x) {
  EXPECT_TRUE(krylov.converged()) << krylov.reason;
  EXPECT_TRUE(newton.converged()) << newton.reason;
  int krylov_steps = 0;
  for (const auto& it : krylov.log) krylov_steps += it.krylov > 0 && !it.chord;
  EXPECT_GT(krylov_steps, 0);
  EXPECT_LT(krylov.factorizations, newton.factorizations);
  EXPECT_LE(krylov.residual, statics.force_tolerance());
  EXPECT_LT((krylov_x - newton_x).cwiseAbs().maxCoeff(), 1e-6);
  return krylov_steps;
}

TEST(Statics, KrylovStepsSaveFactorizationsAndReachTheSameEquilibrium) {
  KrylovBar bar;
  auto& [statics, ws, x] = bar;
  move_right_clamp(statics, x, 2e-3);
  Positions newton_x = x;
  const StaticsResult rn = statics.solve(newton_x);  // from scratch: factors every step
  const StaticsResult rk = statics.solve(ws, x, nullptr, 0, &ws);
  expect_krylov_steps_save_factorizations(statics, rk, x, rn, newton_x);
}

TEST(Statics, KrylovStepsThatMeetNegativeCurvatureSkipTheTrueFactorization) {
  // The bar clamped at both ends and pushed together by 10 %, far past its Euler load (~3 %):
  // its Hessian is indefinite there. A Krylov step preconditioned with the rest state's factor
  // finds a direction of negative curvature, which proves it; Newton then factors only the
  // projected Hessian instead of first trying (and failing on) the true one.
  KrylovBar bar;
  auto& [statics, ws, x] = bar;
  for (int i = 0; i < statics.mesh().node_count(); ++i) x[3 * i] = -0.16 + 0.9 * (x[3 * i] + 0.16);
  const long long factorizations_before = statics_totals().factorizations;
  const StaticsResult r = statics.solve(ws, x, nullptr, 0, &ws);
  const long long factorizations = statics_totals().factorizations - factorizations_before;
  ASSERT_TRUE(r.converged()) << r.reason;
  int negative = 0;
  long long expected = 0;  // one per Newton step, two where the true Hessian was tried first
  for (const auto& it : r.log) {
    negative += it.negative_curvature;
    if (it.negative_curvature) {
      EXPECT_TRUE(it.projected) << "iteration " << it.iteration;
    }
    if (!it.chord && it.krylov == 0 && !it.went_back)
      expected += it.projected && !it.negative_curvature ? 2 : 1;
  }
  EXPECT_GT(negative, 0);
  EXPECT_EQ(factorizations, expected);
  EXPECT_EQ(r.factorizations, expected);
}

TEST(Statics, ASolvesOwnFactorizationPreconditionsItsNextNewtonSteps) {
  // From rest, with no nearby factorization: Newton factors once, and its next steps are
  // solved by conjugate gradients preconditioned with that factor, not by factoring again.
  KrylovBar bar;
  auto& [statics, ws, x] = bar;
  Positions krylov_x = KrylovBar::krylov_scene().world_rest_positions(), newton_x = krylov_x;
  ws.forget_factor();
  const StaticsResult rk = statics.solve(ws, krylov_x);
  Scene exact = KrylovBar::krylov_scene();
  exact.statics.krylov_steps = false;
  const StaticsResult rn = ObjectStatics(exact).solve(newton_x);
  const int krylov_steps =
      expect_krylov_steps_save_factorizations(statics, rk, krylov_x, rn, newton_x);
  EXPECT_EQ(rk.factorizations + krylov_steps, rk.iterations);
}

// A solve from rest: its result, the equilibrium it reached and how many Krylov steps it took.
struct FromRest {
  StaticsResult result;
  Positions x;
  int krylov_steps = 0;
};
FromRest solve_from_rest(const Scene& scene) {
  FromRest out;
  out.x = scene.world_rest_positions();
  out.result = ObjectStatics(scene).solve(out.x);
  for (const auto& it : out.result.log) out.krylov_steps += it.krylov > 0;
  return out;
}

TEST(Statics, OnlyACheapSolvePreconditionsAWarmSolvesKrylovSteps) {
  // A warm re-solve after the clamp moves 2 mm, with the band, whose single-precision solve is
  // cheap, and with CHOLMOD, whose solve costs a good part of a factorization: only the band's
  // takes (inexact) Krylov steps; CHOLMOD's factors at every Newton step. (A cold solve's exact
  // Krylov steps each replace a factorization, with either back-end:
  // AColdSolvesKrylovStepsTakeNewtonsIterates.) Both reach the same equilibrium.
  std::vector<Positions> ends;
  for (const CholeskyBackend backend :
       {CholeskyBackend::Band, CholeskyBackend::CholmodSupernodal}) {
    Scene scene = KrylovBar::krylov_scene();
    scene.statics.backend = backend;
    Positions x;
    const StaticsResult r = warm_resolve(scene, 2e-3, x);
    ASSERT_TRUE(r.converged()) << r.reason;
    int krylov_steps = 0;
    for (const auto& it : r.log) krylov_steps += it.krylov > 0;
    if (backend == CholeskyBackend::Band) {
      EXPECT_GT(krylov_steps, 0);
    } else {
      EXPECT_EQ(krylov_steps, 0);
      EXPECT_GE(r.factorizations, r.iterations);
    }
    ends.push_back(x);
  }
  EXPECT_LT((ends[0] - ends[1]).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(Statics, WhereTheHessianIsIndefiniteKrylovStepsSolveTheProjectedOne) {
  // The bar pushed 10 % together, as above: after the first projected factorization, the next
  // projected Newton steps are solved by conjugate gradients preconditioned with it (their
  // true-Hessian attempt meets negative curvature), without factoring.
  KrylovBar bar;
  auto& [statics, ws, x] = bar;
  for (int i = 0; i < statics.mesh().node_count(); ++i) x[3 * i] = -0.16 + 0.9 * (x[3 * i] + 0.16);
  const StaticsResult r = statics.solve(ws, x, nullptr, 0, &ws);
  ASSERT_TRUE(r.converged()) << r.reason;
  int projected_krylov = 0;
  for (const auto& it : r.log) {
    projected_krylov += it.projected && it.krylov > 0;
    if (it.projected && it.krylov > 0) {
      EXPECT_TRUE(it.negative_curvature) << "iteration " << it.iteration;
    }
  }
  EXPECT_GT(projected_krylov, 0);
  // The equilibrium found is stable: the true Hessian factors there.
  EXPECT_TRUE(statics.solver().factor(statics.terms(), ws, x));
}

TEST(Statics, ChordStepsFollowARigidTurnOfTheWholeObject) {
  // The clamped bar's equilibrium turned 20° about a horizontal axis, clamps included: gravity
  // now pulls partly along the bar, so the equilibrium there differs by a third of a millimetre.
  // The factorization made before the turn, turned with it, still gives chord steps that converge
  // (elasticity's Hessian turns with the object); unturned, it does not, and Newton factors.
  const Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true);
  const Mat3 R = Eigen::AngleAxisd(0.35, Vec3::UnitY()).toRotationMatrix();
  auto solve_turned = [&](bool rotate_chord) {
    Scene s = scene;
    s.statics.rotate_chord = rotate_chord;
    s.statics.krylov_steps = false;
    const ObjectStatics statics(s);
    StaticsWorkspace ws = statics.make_workspace();
    Positions x = s.world_rest_positions();
    EXPECT_TRUE(statics.solve(ws, x).converged());
    for (int i = 0; i < statics.mesh().node_count(); ++i)
      x.segment<3>(3 * i) = R * x.segment<3>(3 * i);
    const Positions turned = x;
    const StaticsResult r = statics.solve(ws, x, nullptr, 0, &ws);
    EXPECT_TRUE(r.converged()) << r.reason;
    EXPECT_GT((x - turned).cwiseAbs().maxCoeff(), 1e-4);  // a real re-solve
    return r;
  };
  const StaticsResult turned = solve_turned(true), plain = solve_turned(false);
  EXPECT_EQ(turned.factorizations, 0);
  EXPECT_GT(plain.factorizations, 0);
}

TEST(Statics, SinglePrecisionChordStepsReachTheSameEquilibrium) {
  // A warm re-solve after a clamp moves: chord and Krylov steps with the factor rounded to
  // float converge on the true residual like those in double, in as many steps or one more,
  // without a factorization, to the same equilibrium.
  const Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true);
  auto warm_resolve = [&](bool single_precision, Positions& x) {
    Scene s = scene;
    s.statics.single_precision_chord = single_precision;
    const ObjectStatics statics(s);
    StaticsWorkspace ws = statics.make_workspace();
    x = s.world_rest_positions();
    EXPECT_TRUE(statics.solve(ws, x).converged());
    move_right_clamp(statics, x, 2e-3);
    const StaticsResult r = statics.solve(ws, x, nullptr, 0, &ws);
    EXPECT_TRUE(r.converged()) << r.reason;
    EXPECT_LE(r.residual, statics.force_tolerance());
    return r;
  };
  Positions single_x, double_x;
  const StaticsResult single = warm_resolve(true, single_x), exact = warm_resolve(false, double_x);
  EXPECT_EQ(single.factorizations, 0);
  EXPECT_EQ(exact.factorizations, 0);
  EXPECT_LE(single.iterations, exact.iterations + 1);
  EXPECT_LT((single_x - double_x).cwiseAbs().maxCoeff(), 1e-6);
}

TEST_P(StaticsEachSolver, AStopRequestEndsTheSolveAndSaysSo) {
  const Scene scene =
      with_solver(bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true));
  const ObjectStatics statics(scene);
  StaticsWorkspace ws = statics.make_workspace();
  Positions x = scene.world_rest_positions();
  int asked = 0;
  const StaticsResult r = statics.solve(ws, x, nullptr, 0, nullptr, [&] { return ++asked > 1; });
  EXPECT_EQ(r.status, StaticsStatus::NotConverged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_NE(r.reason.find("stopped (time limit)"), std::string::npos) << r.reason;
  EXPECT_TRUE(x.allFinite());
  Positions again = x;  // the same solve, not stopped, goes on from there and converges
  EXPECT_TRUE(statics.solve(ws, again).converged());
}

TEST_P(StaticsEachSolver, CompressedSlenderBarIsNotPositiveDefinite) {
  // Clamped at both ends and shortened 10 % while straight: three times the Euler buckling
  // strain (4π² I / A L² ≈ 3 %), so bending modes have negative stiffness there.
  Scene scene = with_solver(bar_scene({16, 4, 4}, material_from_youngs(2e5, 0.3, 40), 0.001, true));
  scene.gravity = Vec3::Zero();
  const ObjectStatics statics(scene);
  const StaticsSolver& solver = statics.solver();
  StaticsWorkspace ws = statics.make_workspace();
  Positions x = scene.world_rest_positions();
  EXPECT_TRUE(solver.factor(statics.terms(), ws, x));
  for (int i = 0; i < statics.mesh().node_count(); ++i) x[3 * i] *= 0.9;
  EXPECT_FALSE(solver.factor(statics.terms(), ws, x));
  EXPECT_THROW(solver.solve_with_factor(ws, Eigen::MatrixXd::Ones(x.size(), 1)),
               std::runtime_error);
  // Shortened 0.1 %: far from buckling, still positive definite.
  x = scene.world_rest_positions();
  for (int i = 0; i < statics.mesh().node_count(); ++i) x[3 * i] *= 0.999;
  EXPECT_TRUE(solver.factor(statics.terms(), ws, x));
}

TEST_P(StaticsEachSolver, WarmStartAtEquilibriumNeedsNoIteration) {
  const Scene scene =
      with_solver(bar_scene({8, 2, 2}, material_from_youngs(1e5, 0.3, 40), 0.001, true));
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  ASSERT_TRUE(statics.solve(x).converged());
  const StaticsResult again = statics.solve(x);
  EXPECT_TRUE(again.converged());
  EXPECT_EQ(again.iterations, 0);
}

// Mean vertical displacement of the free end of a cantilever, its statics factored by `backend`.
double cantilever_tip_deflection(const std::array<int, 3>& cells, const Material& m,
                                 CholeskyBackend backend) {
  const Scene scene = test::with_solver(bar_scene(cells, m, 1e-6, false), backend);
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  EXPECT_TRUE(r.converged()) << r.reason;
  double sum = 0;
  int count = 0;
  for (int i = 0; i < statics.mesh().node_count(); ++i)
    if (scene.object_mesh->rest_positions()[i].x() > 0.16 - 1e-9) {
      sum += x[3 * i + 2] - scene.object_mesh->rest_positions()[i].z();
      ++count;
    }
  return sum / count;
}

TEST_P(StaticsEachSolver, CantileverApproachesEulerBernoulliWithRefinement) {
  // Small load: δ/L ≈ 0.3 %, so linear beam theory applies. ν = 0.05 keeps the
  // cross-section nearly free of Poisson coupling that beam theory ignores.
  const double E = 1e6, rho = 20, g = 9.81, L = 0.32, h = 0.03;
  const Material m = material_from_youngs(E, 0.05, rho);
  const double q = rho * g * h * h, I = h * h * h * h / 12;
  const double euler_bernoulli = q * L * L * L * L / (8 * E * I);
  std::vector<double> errors;
  for (const auto& cells : {std::array<int, 3>{8, 1, 1}, {16, 2, 2}, {32, 4, 4}}) {
    const double tip = -cantilever_tip_deflection(cells, m, GetParam());
    errors.push_back(std::abs(tip - euler_bernoulli) / euler_bernoulli);
  }
  // Linear tets lock in bending (too stiff: 80 %, 51 %, 21 % short on this machine);
  // each refinement must close the gap markedly.
  EXPECT_LT(errors[1], errors[0] / 1.4);
  EXPECT_LT(errors[2], errors[1] / 1.8);
  EXPECT_LT(errors[2], 0.25) << "finest mesh relative error";
}

TEST(Statics, ObjectThatNothingHoldsIsReportedSingular) {
  Scene scene = bar_scene({4, 1, 1}, material_from_youngs(1e5, 0.3, 40), 0.001, false);
  scene.fixed.reset();
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  EXPECT_EQ(r.status, StaticsStatus::Singular);
  EXPECT_NE(r.reason.find("nothing holds"), std::string::npos) << r.reason;
  EXPECT_TRUE(x.allFinite());
}

TEST_P(StaticsEachSolver, BarPinnedAtOneNodeIsSingularNotNaN) {
  // One fixed node: the bar may still spin about it, so the Hessian is singular.
  Scene scene = with_solver(bar_scene({4, 1, 1}, material_from_youngs(1e5, 0.3, 40), 0.001, false));
  scene.fixed = NodeSelection{.box = std::nullopt, .nodes = {0}};
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  EXPECT_FALSE(r.converged()) << r.reason;
  EXPECT_TRUE(x.allFinite());
  if (test::refuses_tiny_pivots(GetParam())) {
    EXPECT_EQ(r.status, StaticsStatus::Singular) << r.reason;
    EXPECT_NE(r.reason.find("singular"), std::string::npos) << r.reason;
  }
}

TEST_P(StaticsEachSolver, UnconvergedSolveIsNeverReportedConverged) {
  Scene scene = with_solver(bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true));
  scene.statics.max_iterations = 1;
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  const StaticsResult r = statics.solve(x);
  EXPECT_EQ(r.status, StaticsStatus::NotConverged);
  EXPECT_NE(r.reason.find("after 1 iterations"), std::string::npos) << r.reason;
}

// A solver for `statics`'s problem with the watchdog after `watchdog_iterations` (0: off).
StaticsSolver with_watchdog(const ObjectStatics& statics, int watchdog_iterations) {
  StaticsOptions options = statics.solver().options();
  options.watchdog_iterations = watchdog_iterations;
  return StaticsSolver(statics.mesh().node_count(), statics.fixed_node(), options);
}

// Statics from rest with the watchdog after `watchdog_iterations` (0: off); x the answer.
StaticsResult solve_from_rest(const ObjectStatics& statics, int watchdog_iterations, Positions& x) {
  const StaticsSolver solver = with_watchdog(statics, watchdog_iterations);
  StaticsWorkspace ws = solver.make_workspace();
  x = statics.mesh().rest_vector();
  return solver.solve(statics.terms(), ws, x);
}

// Largest distance between the nodes of two position vectors.
double largest_distance(const Positions& a, const Positions& b) {
  return (a - b).reshaped(3, a.size() / 3).colwise().norm().maxCoeff();
}

TEST(Statics, WatchdogSavesIterationsOnASoftCantileverFromRest) {
  // A foam cantilever sags a third of its length: from rest Newton's full step (the linear
  // solution) stretches it, and the energy test cut it to a fraction.
  const Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, false);
  const ObjectStatics statics(scene);
  Positions x_on, x_off;
  const StaticsResult r_on = solve_from_rest(statics, 6, x_on);
  const StaticsResult r_off = solve_from_rest(statics, 0, x_off);
  ASSERT_TRUE(r_on.converged()) << r_on.reason;
  ASSERT_TRUE(r_off.converged()) << r_off.reason;
  // 8 against 15 on this machine.
  EXPECT_LE(r_on.iterations, 10);
  EXPECT_LE(r_on.iterations + 4, r_off.iterations);
  // The first step was the relaxed one: taken in full although it raised the energy; none
  // was undone.
  ASSERT_GE(r_on.log.size(), 2u);
  EXPECT_TRUE(r_on.log[0].relaxed);
  EXPECT_EQ(r_on.log[0].step_length, 1);
  EXPECT_GT(r_on.log[1].energy, r_on.log[0].energy);
  for (const auto& it : r_on.log) EXPECT_FALSE(it.went_back);
  EXPECT_LT(r_on.energy, r_on.log[0].energy);
  // The same equilibrium; the tip hangs centimetres low.
  EXPECT_LT(largest_distance(x_on, x_off), 1e-6);
  EXPECT_GT(largest_distance(x_on, scene.world_rest_positions()), 0.05);
}

TEST(Statics, AColdSolvesKrylovStepsTakeNewtonsIterates) {
  // A cold solve factors once and solves its next Newton steps by conjugate gradients
  // preconditioned with that factor, as far as the tolerance: as many iterations as exact
  // Newton (two on the stiff bar, as DOLFINx's; scripts/compare_dolfinx.py) and the same
  // equilibrium. On the soft cantilever, whose large steps change the Hessian much, those
  // steps give up early and Newton factors anew: again exact Newton's iterations.
  const Scene stiff = bar_scene({40, 6, 6}, material_from_youngs(2e5, 0.3, 40), 0.001, true);
  const Scene soft = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, false);
  for (const Scene& scene : {stiff, soft}) {
    Scene exact = scene;
    exact.statics.krylov_steps = false;
    const FromRest krylov = solve_from_rest(scene), newton = solve_from_rest(exact);
    ASSERT_TRUE(krylov.result.converged()) << krylov.result.reason;
    ASSERT_TRUE(newton.result.converged()) << newton.result.reason;
    EXPECT_EQ(newton.krylov_steps, 0);
    EXPECT_EQ(krylov.result.iterations, newton.result.iterations);
    EXPECT_LE(krylov.result.factorizations, newton.result.factorizations - krylov.krylov_steps);
    // Each converged to the force tolerance: sub-micrometre apart.
    EXPECT_LT(largest_distance(krylov.x, newton.x), 1e-7);
  }
  const FromRest krylov = solve_from_rest(stiff);
  EXPECT_EQ(krylov.result.iterations, 2);
  EXPECT_EQ(krylov.result.factorizations, 1);
}

TEST(Statics, WatchdogGoesBackWhenTheEnergyDoesNotFallInTime) {
  // One iteration is too few for the cantilever to swing below its starting energy: the
  // solve returns to the rest state and descends from there as without the watchdog.
  const Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, false);
  const ObjectStatics statics(scene);
  Positions x, x_off;
  const StaticsResult r = solve_from_rest(statics, 1, x);
  const StaticsResult r_off = solve_from_rest(statics, 0, x_off);
  ASSERT_TRUE(r.converged()) << r.reason;
  ASSERT_TRUE(r_off.converged()) << r_off.reason;
  ASSERT_GE(r.log.size(), 2u);
  EXPECT_TRUE(r.log[0].relaxed);
  EXPECT_TRUE(r.log[1].went_back);
  EXPECT_EQ(r.log[1].energy, r.log[0].energy);  // back at rest
  EXPECT_EQ(r.iterations, r_off.iterations + 1);
  EXPECT_LT(largest_distance(x, x_off), 1e-6);
}

TEST(Statics, WatchdogEndingUnconvergedReturnsTheStateBeforeItsStep) {
  // Stopped by the iteration limit during the watch: the state before the relaxed step (here
  // rest), not the stretched one, with its residual.
  const Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, false);
  const ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  StaticsWorkspace ws = statics.make_workspace();
  const StaticsResult r = statics.solver().solve(statics.terms(), ws, x, 2);
  EXPECT_EQ(r.status, StaticsStatus::NotConverged);
  ASSERT_FALSE(r.log.empty());
  EXPECT_TRUE(r.log[0].relaxed);
  EXPECT_EQ(x, scene.world_rest_positions());
  EXPECT_EQ(r.residual, r.log[0].residual);
  EXPECT_EQ(r.energy, r.log[0].energy);
}

TEST(Statics, WarmSolvesWithANearbyFactorNeverRelax) {
  // The optimizer's warm solves (a chord source given) keep the energy test on every step.
  const Scene scene = bar_scene({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), 0.001, true);
  Positions x;
  const StaticsResult r = warm_resolve(scene, 2e-2, x);
  ASSERT_TRUE(r.converged()) << r.reason;
  for (const auto& it : r.log) EXPECT_FALSE(it.relaxed || it.went_back);
}

INSTANTIATE_TEST_SUITE_P(Each, StaticsEachSolver, testing::ValuesIn(test::kLinearSolvers),
                         test::linear_solver_name);

}  // namespace
}  // namespace shapectl
