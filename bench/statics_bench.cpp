// Statics benchmarks: the default foam bar (1,536 tets) clamped at both ends, solved from rest
// and re-solved warm after one clamp moves by 1 mm; larger boxes for scaling; the Cholesky
// backends side by side to pick the crossover.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <shapectl/linalg/band_cholesky.hpp>
#include <shapectl/mesh/box_mesh.hpp>
#include <shapectl/sim/object_statics.hpp>

namespace shapectl {
namespace {

// A bar of cells (n, n/4, n/4)... clamped 10 mm deep at both ends.
Scene clamped_bar(const std::array<int, 3>& cells) {
  Scene s;
  s.object_mesh = std::make_shared<const TetMesh>(make_box_mesh({0.32, 0.03, 0.03}, cells));
  s.material = material_from_youngs(2e5, 0.3, 40);
  NodeSelection fixed;
  for (int i = 0; i < s.object_mesh->node_count(); ++i)
    if (std::abs(s.object_mesh->rest_positions()[i].x()) > 0.16 - 0.011) fixed.nodes.push_back(i);
  s.fixed = fixed;
  return s;
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

void full_solve(benchmark::State& state, std::array<int, 3> cells,
                std::optional<SparseCholesky::Backend> backend) {
  Scene scene = clamped_bar(cells);
  scene.statics.backend = backend;
  ObjectStatics statics(scene);
  int iterations = 0;
  for (auto _ : state) {
    ObjectStatics fresh(scene);  // symbolic analysis included: a full solve from scratch
    Positions x = scene.world_rest_positions();
    const StaticsResult r = fresh.solve(x);
    if (!r.converged()) state.SkipWithError(r.reason.c_str());
    iterations = r.iterations;
  }
  state.counters["tets"] = statics.mesh().tet_count();
  state.counters["newton_iterations"] = iterations;
  state.counters["peak_rss_MB"] = peak_rss_mb();
}

void BM_StaticsFullSolve(benchmark::State& state) { full_solve(state, {16, 4, 4}, std::nullopt); }
BENCHMARK(BM_StaticsFullSolve)->Unit(benchmark::kMillisecond);

// From the rest shape with the per-mesh set-up (symbolic analysis) already done; Newton only
// (no chord steps: no earlier factorization helps).
void BM_StaticsSolveFromRest(benchmark::State& state) {
  Scene scene = clamped_bar({16, 4, 4});
  ObjectStatics statics(scene);
  StaticsWorkspace ws = statics.make_workspace();
  int iterations = 0;
  for (auto _ : state) {
    Positions x = scene.world_rest_positions();
    ws.forget_factor();  // the analysis stays
    const StaticsResult r = statics.solve(ws, x);
    if (!r.converged()) state.SkipWithError(r.reason.c_str());
    iterations = r.iterations;
  }
  state.counters["newton_iterations"] = iterations;
}
BENCHMARK(BM_StaticsSolveFromRest)->Unit(benchmark::kMillisecond);

void BM_StaticsWarmResolve(benchmark::State& state) {
  const Scene scene = clamped_bar({16, 4, 4});
  ObjectStatics statics(scene);
  StaticsWorkspace ws = statics.make_workspace();
  Positions x = scene.world_rest_positions();
  if (!statics.solve(ws, x).converged()) state.SkipWithError("initial solve failed");
  // Nodes of the +x clamp: move them 1 mm along x and back, alternately.
  std::vector<int> clamp;
  for (int i = 0; i < statics.mesh().node_count(); ++i)
    if (statics.fixed_node()[i] && statics.mesh().rest_positions()[i].x() > 0) clamp.push_back(i);
  double direction = 1;
  int iterations = 0;
  for (auto _ : state) {
    for (int i : clamp) x[3 * i] += direction * 1e-3;
    direction = -direction;
    const StaticsResult r =
        statics.solve(ws, x, nullptr, 0, &ws);  // chord steps with the last factor
    if (!r.converged()) state.SkipWithError(r.reason.c_str());
    iterations = r.iterations;
  }
  state.counters["newton_iterations"] = iterations;
}
BENCHMARK(BM_StaticsWarmResolve)->Unit(benchmark::kMillisecond);

void BM_StaticsFullSolve10k(benchmark::State& state) {
  full_solve(state, {40, 8, 5}, std::nullopt);
}
void BM_StaticsFullSolve50k(benchmark::State& state) {
  full_solve(state, {64, 12, 11}, std::nullopt);
}
BENCHMARK(BM_StaticsFullSolve10k)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_StaticsFullSolve50k)->Unit(benchmark::kMillisecond)->Iterations(1);

// Backend crossover: the same solve with each Cholesky.
void BM_BackendLDLT(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  full_solve(state, {4 * n, n, n}, SparseCholesky::Backend::SimplicialLDLT);
}
void BM_BackendCholmod(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  full_solve(state, {4 * n, n, n}, SparseCholesky::Backend::CholmodSupernodal);
}
void BM_BackendBand(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  full_solve(state, {4 * n, n, n}, SparseCholesky::Backend::Band);
}
BENCHMARK(BM_BackendLDLT)
    ->Arg(4)
    ->Arg(6)
    ->Arg(8)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);
BENCHMARK(BM_BackendBand)
    ->Arg(4)
    ->Arg(6)
    ->Arg(8)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);
BENCHMARK(BM_BackendCholmod)
    ->Arg(4)
    ->Arg(6)
    ->Arg(8)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

// One numeric factorization of the default bar's Hessian at its equilibrium, and one solve
// with 14 right-hand sides (a sensitivity dx̂/dθ for a two-arm robot), each backend.
void factorize(benchmark::State& state, SparseCholesky::Backend backend, int rhs_columns) {
  const Scene scene = clamped_bar({16, 4, 4});
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  if (!statics.solve(x).converged()) state.SkipWithError("statics failed");
  const SparseMatrix H = statics.hessian(x);
  SparseCholesky cholesky(backend);
  cholesky.analyze(H);
  if (!cholesky.factorize(H)) state.SkipWithError("not positive definite");
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Ones(H.rows(), rhs_columns);
  for (auto _ : state) {
    if (rhs_columns == 0) benchmark::DoNotOptimize(cholesky.factorize(H));
    else benchmark::DoNotOptimize(cholesky.solve(rhs));
  }
}
BENCHMARK_CAPTURE(factorize, ldlt, SparseCholesky::Backend::SimplicialLDLT, 0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(factorize, band, SparseCholesky::Backend::Band, 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(factorize, cholmod, SparseCholesky::Backend::CholmodSupernodal, 0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(factorize, solve14_ldlt, SparseCholesky::Backend::SimplicialLDLT, 14)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(factorize, solve14_band, SparseCholesky::Backend::Band, 14)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(factorize, solve14_cholmod, SparseCholesky::Backend::CholmodSupernodal, 14)
    ->Unit(benchmark::kMillisecond);

// The pieces of one optimizer iteration on a refined bar (12,288 tets: the 12k size),
// at its equilibrium: energy, gradient, Hessian assembly, numeric factorization, a solve with
// 14 right-hand sides (dx̂/dθ for two 7-joint arms; or `rhs_columns`). EnergyAndGradient: the
// terms' fused value_and_add_gradient (one pass where a term has one). Which piece dominates
// decides what to cut. Arg(n): a bar of 4n × n × n cells (4: the default bar, 8: 12k tets).
// Assemble: the workspace's assembler with its pattern built (what every Newton and Krylov step
// pays); FactorOnly: the numeric factorization of the matrix already assembled.
// The default bar and the 12k one, in milliseconds.
void both_bars(benchmark::internal::Benchmark* b) {
  b->Arg(4)->Arg(8)->Unit(benchmark::kMillisecond);
}
// Also 25k and 50k tets (bandwidths 368 and 593), where OpenBLAS's threads come in.
void four_bars(benchmark::internal::Benchmark* b) {
  b->Arg(4)->Arg(8)->Arg(10)->Arg(13)->Unit(benchmark::kMillisecond);
}
enum class Piece {
  Energy,
  Gradient,
  EnergyAndGradient,
  Hessian,
  Assemble,
  FactorOnly,
  Factorize,
  Solve,
  Precondition,
  HessianProduct
};
void piece(benchmark::State& state, Piece which, std::optional<SparseCholesky::Backend> backend,
           int rhs_columns = 14) {
  const int n = static_cast<int>(state.range(0));
  Scene scene = clamped_bar({4 * n, n, n});
  scene.statics.backend = backend;
  ObjectStatics statics(scene);
  StaticsWorkspace ws = statics.make_workspace();
  Positions x = scene.world_rest_positions();
  if (!statics.solve(ws, x).converged()) state.SkipWithError("statics failed");
  const EnergyTerms terms = statics.terms();
  const StaticsSolver& solver = statics.solver();
  if (!solver.factor(terms, ws, x)) state.SkipWithError("not positive definite");
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Ones(x.size(), rhs_columns);
  for (auto _ : state) {
    switch (which) {
      case Piece::Energy: benchmark::DoNotOptimize(solver.energy(terms, x)); break;
      case Piece::Gradient: benchmark::DoNotOptimize(solver.gradient(terms, x)); break;
      case Piece::EnergyAndGradient: {
        Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
        double e = 0;
        for (const EnergyTerm* t : terms) e += t->value_and_add_gradient(x, g);
        benchmark::DoNotOptimize(e);
        benchmark::DoNotOptimize(g.data());
        break;
      }
      case Piece::Hessian: benchmark::DoNotOptimize(solver.hessian(terms, x)); break;
      case Piece::Assemble:
        benchmark::DoNotOptimize(ws.assembler.assemble(terms, x, false).valuePtr());
        break;
      case Piece::FactorOnly:
        benchmark::DoNotOptimize(ws.cholesky.factorize(ws.assembler.matrix()));
        break;
      case Piece::Factorize: benchmark::DoNotOptimize(solver.factor(terms, ws, x)); break;
      case Piece::Solve: benchmark::DoNotOptimize(solver.solve_with_factor(ws, rhs)); break;
      case Piece::Precondition:
        benchmark::DoNotOptimize(ws.cholesky.solve_preconditioner(rhs.col(0)));
        break;
      case Piece::HessianProduct: {
        const Eigen::VectorXd Hv =
            ws.assembler.matrix().selfadjointView<Eigen::Lower>() * rhs.col(0);
        benchmark::DoNotOptimize(Hv.data());
        break;
      }
    }
  }
  state.counters["tets"] = statics.mesh().tet_count();
}
BENCHMARK_CAPTURE(piece, energy, Piece::Energy, std::nullopt)->Apply(four_bars);
BENCHMARK_CAPTURE(piece, gradient, Piece::Gradient, std::nullopt)->Apply(four_bars);
BENCHMARK_CAPTURE(piece, energy_and_gradient, Piece::EnergyAndGradient, std::nullopt)
    ->Apply(four_bars);
BENCHMARK_CAPTURE(piece, hessian, Piece::Hessian, std::nullopt)
    ->Arg(4)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(piece, assemble, Piece::Assemble, std::nullopt)->Apply(four_bars);
BENCHMARK_CAPTURE(piece, factor_only_band, Piece::FactorOnly, SparseCholesky::Backend::Band)
    ->Apply(four_bars);
BENCHMARK_CAPTURE(piece, assemble_and_factor_auto, Piece::Factorize, std::nullopt)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(piece, assemble_and_factor_band, Piece::Factorize, SparseCholesky::Backend::Band)
    ->Arg(4)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(piece, assemble_and_factor_cholmod, Piece::Factorize,
                  SparseCholesky::Backend::CholmodSupernodal)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond);
const auto kCholmod = SparseCholesky::Backend::CholmodSupernodal;
BENCHMARK_CAPTURE(piece, solve14_auto, Piece::Solve, std::nullopt)->Apply(both_bars);
BENCHMARK_CAPTURE(piece, solve14_cholmod, Piece::Solve, kCholmod)->Apply(both_bars);
// One right-hand side (a Newton or chord step), and two and four: where the band's blocked
// many-column solve starts to pay.
BENCHMARK_CAPTURE(piece, solve1_auto, Piece::Solve, std::nullopt, 1)->Apply(both_bars);
BENCHMARK_CAPTURE(piece, solve2_auto, Piece::Solve, std::nullopt, 2)->Apply(both_bars);
BENCHMARK_CAPTURE(piece, solve4_auto, Piece::Solve, std::nullopt, 4)->Apply(both_bars);
BENCHMARK_CAPTURE(piece, solve1_cholmod, Piece::Solve, kCholmod, 1)->Apply(both_bars);

// What one conjugate-gradient product of a Krylov step costs: the single-precision solve with
// the factor (the preconditioner) and the product with the assembled Hessian.
BENCHMARK_CAPTURE(piece, precondition, Piece::Precondition, std::nullopt)->Apply(four_bars);
BENCHMARK_CAPTURE(piece, hessian_product, Piece::HessianProduct, std::nullopt)->Apply(four_bars);

// The band factorization alone (no assembly), with its flop rate: BandCholesky::flops() per
// CPU second of the calling thread, the share of one core's peak that dpbtrf reaches below 192
// sub-diagonals; from there the factorization's second thread makes the rate an overestimate
// (compare wall times).
void BM_BandFactorize(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Scene scene = clamped_bar({4 * n, n, n});
  ObjectStatics statics(scene);
  Positions x = scene.world_rest_positions();
  if (!statics.solve(x).converged()) state.SkipWithError("statics failed");
  const SparseMatrix H = statics.hessian(x);
  SparseCholesky cholesky(SparseCholesky::Backend::Band);  // sets OpenBLAS's threads as in use
  cholesky.analyze(H);
  if (!cholesky.factorize(H)) state.SkipWithError("not positive definite");
  for (auto _ : state) benchmark::DoNotOptimize(cholesky.factorize(H));
  BandCholesky band;  // the same ordering, for its size and flop count
  band.analyze(H);
  state.counters["bandwidth"] = band.bandwidth();
  state.counters["band_MB"] = band.storage_bytes() / 1e6;
  state.counters["flops"] =
      benchmark::Counter(band.flops(), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_BandFactorize)->Apply(four_bars);

}  // namespace
}  // namespace shapectl

BENCHMARK_MAIN();
