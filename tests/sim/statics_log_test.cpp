// The sequence of steps StaticsSolver::solve takes (chord, Krylov, Newton, projected, relaxed,
// went back, line-search cuts) and how it ends, on one scene per path through the solve. The
// sequences were recorded from the solver before its loop was cut into phases (issue 33): they
// pin the order in which the phases decide, which the behaviour tests (statics_test.cpp) only
// sample. Each test also prints its full log and a fingerprint of the positions in round-trip
// precision, for comparing two builds bit for bit (`sim_tests --gtest_filter='StaticsLog.*'`).
#include <shapectl/sim/object_statics.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

#include <shapectl/mesh/box_mesh.hpp>

namespace shapectl {
namespace {

// The 0.32 m bar of statics_test.cpp: held by a 1 mm clamp at -x, and at +x too if `both_ends`.
Scene bar(const std::array<int, 3>& cells, const Material& material, bool both_ends) {
  Scene s;
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({0.32, 0.03, 0.03}, cells));
  s.material = material;
  NodeSelection fixed;
  fixed.box = AlignedBox{Vec3(-1, -1, -1), Vec3(-0.159, 1, 1)};
  s.fixed = fixed;
  if (both_ends)
    for (int i = 0; i < s.object_mesh->node_count(); ++i)
      if (s.object_mesh->rest_positions()[i].x() > 0.159) s.fixed->nodes.push_back(i);
  return s;
}
Scene foam_bar() { return bar({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), true); }
Scene foam_cantilever() { return bar({16, 4, 4}, material_from_youngs(2e4, 0.3, 60), false); }

void move_right_clamp(const ObjectStatics& statics, Positions& x, double dy) {
  for (int i = 0; i < statics.mesh().node_count(); ++i)
    if (statics.fixed_node()[i] && statics.mesh().rest_positions()[i].x() > 0) x[3 * i + 1] += dy;
}
void shorten(Positions& x, double factor) {
  for (int i = 0; i < x.size() / 3; ++i) x[3 * i] = -0.16 + factor * (x[3 * i] + 0.16);
}

// One code per iteration: C chord, K<n> Krylov with n products, N Newton, P projected Newton,
// pK<n> projected Krylov, B went back; then ! negative curvature, r relaxed, /<k> step 1/k.
std::string steps(const StaticsResult& r) {
  std::string s;
  for (const NewtonIterate& it : r.log) {
    if (!s.empty()) s += ' ';
    if (it.went_back) s += 'B';
    else if (it.chord) s += 'C';
    else if (it.krylov > 0) s += (it.projected ? "pK" : "K") + std::to_string(it.krylov);
    else s += it.projected ? 'P' : 'N';
    if (it.negative_curvature) s += '!';
    if (it.relaxed) s += 'r';
    if (!it.went_back && it.step_length != 1)
      s += '/' + std::to_string(std::lround(1 / it.step_length));
  }
  return s;
}

// "status iterations factorizations: steps".
std::string summary(const StaticsResult& r) {
  return std::string(to_string(r.status)) + ' ' + std::to_string(r.iterations) + ' ' +
         std::to_string(r.factorizations) + ": " + steps(r);
}

// Prints every number of the log and an FNV-1a hash of the positions' bits.
void print_log(const char* name, const StaticsResult& r, const Positions& x) {
  std::uint64_t hash = 14695981039346656037ull;
  for (int i = 0; i < x.size(); ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, &x[i], sizeof bits);
    for (int b = 0; b < 8; ++b) hash = (hash ^ ((bits >> (8 * b)) & 0xff)) * 1099511628211ull;
  }
  std::printf("log %s: %s | %s | residual %.17g energy %.17g x %016" PRIx64 "\n", name,
              summary(r).c_str(), r.reason.c_str(), r.residual, r.energy, hash);
  for (const NewtonIterate& it : r.log)
    std::printf("log %s %d: %.17g %.17g %.17g %.17g\n", name, it.iteration, it.residual, it.energy,
                it.step, it.step_length);
}

// A cold solve of `scene` from rest (or from `start`) in a fresh workspace, with the
// scene's options changed by `options`: the summary, printed.
struct Cold {
  int max_iterations = 0;
  StopRequest stop = {};
  std::function<void(Positions&)> start = {};
  std::function<void(StaticsOptions&)> options = {};
};
std::string cold(const char* name, const Scene& scene, const Cold& how = {}) {
  const ObjectStatics statics(scene);
  StaticsOptions options = statics.solver().options();
  if (how.options) how.options(options);
  const StaticsSolver solver(statics.mesh().node_count(), statics.fixed_node(), options);
  StaticsWorkspace ws = solver.make_workspace();
  Positions x = scene.world_rest_positions();
  if (how.start) how.start(x);
  const StaticsResult r =
      solver.solve(statics.terms(), ws, x, how.max_iterations, nullptr, how.stop);
  print_log(name, r, x);
  return summary(r);
}

// Solves `scene` from rest, changes the state by `change` and solves again with the first
// solve's factor as the chord: the second solve's summary, printed.
std::string warm(const char* name, const Scene& scene,
                 const std::function<void(const ObjectStatics&, Positions&)>& change) {
  const ObjectStatics statics(scene);
  StaticsWorkspace ws = statics.make_workspace();
  Positions x = scene.world_rest_positions();
  EXPECT_TRUE(statics.solve(ws, x).converged());
  change(statics, x);
  const StaticsResult r = statics.solve(ws, x, nullptr, 0, &ws);
  print_log(name, r, x);
  return summary(r);
}

TEST(StaticsLog, ColdSolveFactorsOnceThenTakesExactKrylovSteps) {
  EXPECT_EQ(cold("cold", foam_bar()), "converged 3 2: Nr K8 N");
}

TEST(StaticsLog, WarmSolveTakesChordSteps) {
  EXPECT_EQ(warm("chord", foam_bar(),
                 [](const ObjectStatics& s, Positions& x) { move_right_clamp(s, x, 2e-3); }),
            "converged 3 0: C C C");
}

TEST(StaticsLog, WarmSolveWithoutChordStepsTakesKrylovSteps) {
  Scene scene = foam_bar();
  scene.statics.chord_steps = false;
  EXPECT_EQ(warm("krylov", scene,
                 [](const ObjectStatics& s, Positions& x) { move_right_clamp(s, x, 2e-3); }),
            "converged 2 0: K2 K2");
}

TEST(StaticsLog, NegativeCurvatureSkipsTheTrueFactorization) {
  Scene scene = foam_bar();
  scene.statics.chord_steps = false;
  EXPECT_EQ(warm("negative", scene, [](const ObjectStatics&, Positions& x) { shorten(x, 0.9); }),
            "converged 8 1: pK2! pK5! pK5! K12 K4 N K2 K2");
}

TEST(StaticsLog, ColdSolveOfAnIndefiniteStartProjects) {
  EXPECT_EQ(cold("indefinite", foam_bar(), {.start = [](Positions& x) { shorten(x, 0.9); }}),
            "converged 8 11: Pr P P P N N N K4");
}

TEST(StaticsLog, WatchdogStepIsKept) {
  EXPECT_EQ(cold("watchdog kept", foam_cantilever()), "converged 8 11: Nr N P P P P N K1");
}

TEST(StaticsLog, WatchdogGoesBack) {
  EXPECT_EQ(cold("watchdog back", foam_cantilever(),
                 {.options = [](StaticsOptions& o) { o.watchdog_iterations = 1; }}),
            "converged 16 11: Nr B K1/8 N N/2 N N N N/2 N N/2 N K8 N K5 K6 K4");
}

TEST(StaticsLog, IterationLimitDuringTheWatchRestores) {
  EXPECT_EQ(cold("watchdog limit", foam_cantilever(), {.max_iterations = 2}),
            "not converged 2 2: Nr N");
}

TEST(StaticsLog, IterationLimit) {
  EXPECT_EQ(cold("limit", foam_bar(), {.max_iterations = 1}), "not converged 1 1: Nr");
}

TEST(StaticsLog, StopRequestBeforeAnIteration) {
  int asked = 0;
  EXPECT_EQ(cold("stop", foam_bar(), {.stop = [&] { return ++asked > 1; }}),
            "not converged 1 1: Nr");
}

TEST(StaticsLog, StopRequestDuringTheStabilityCheck) {
  // The first ask is before iteration 0; the second, after the true Hessian failed to factor.
  int asked = 0;
  EXPECT_EQ(cold("stop projected", foam_bar(),
                 {.stop = [&] { return ++asked > 1; },
                  .start = [](Positions& x) { shorten(x, 0.9); }}),
            "not converged 0 1: ");
}

TEST(StaticsLog, SingularSystem) {
  Scene scene = bar({4, 1, 1}, material_from_youngs(1e5, 0.3, 40), false);
  scene.fixed = NodeSelection{.box = std::nullopt, .nodes = {0}};
  EXPECT_EQ(cold("singular", scene), "singular 0 2: ");
}

TEST(StaticsLog, NonFiniteTolerance) {
  const auto infinite = [](StaticsOptions& o) {
    o.force_tolerance = std::numeric_limits<double>::infinity();
  };
  EXPECT_EQ(cold("infinite tolerance", foam_bar(), {.options = infinite}), "not converged 0 0: ");
}

TEST(StaticsLog, InvertedStart) {
  EXPECT_EQ(cold("inverted", foam_bar(), {.start = [](Positions& x) { x = -x; }}),
            "inverted 0 0: ");
}

}  // namespace
}  // namespace shapectl
