#include <shapectl/control/optimize.hpp>

#include <chrono>
#include <cmath>

#include <shapectl/enum_names.hpp>

namespace shapectl {

namespace {
constexpr auto kTerminations =
    enum_names<Termination>(std::pair{Termination::Converged, "converged"},
                            std::pair{Termination::IterationLimit, "iteration limit"},
                            std::pair{Termination::TimeLimit, "time limit"},
                            std::pair{Termination::Stuck, "stuck"},
                            std::pair{Termination::Failed, "failed"});
}  // namespace

const char* to_string(Termination termination) { return kTerminations.name(termination); }

bool parse(std::string_view name, Termination* termination) {
  return kTerminations.parse(name, termination);
}

OptimizeResult optimize(const ReducedObjective& objective, Optimizer& optimizer, Evaluation start,
                        const OptimizeOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const std::function<double()> elapsed =
      options.clock ? options.clock : std::function<double()>([t0] {
        return std::chrono::duration<double>(Clock::now() - t0).count();
      });
  OptimizeResult result;
  result.best = std::move(start);
  result.history.push_back({0, 0.0, result.best.error.mean, result.best.objective});
  optimizer.reset();
  optimizer.out_of_time = [&] { return elapsed() > options.max_seconds; };
  // The budget refers to this call's locals: gone when it returns or throws.
  struct ClearBudget {
    Optimizer& optimizer;
    ~ClearBudget() { optimizer.out_of_time = nullptr; }
  } clear_budget{optimizer};
  for (int it = 1;; ++it) {
    if (it > options.max_iterations) {
      result.termination = Termination::IterationLimit;
      result.reason = "iteration limit (" + std::to_string(options.max_iterations) + ") reached";
      break;
    }
    if (optimizer.out_of_time()) {
      result.termination = Termination::TimeLimit;
      result.reason = "time limit reached";
      break;
    }
    const StepOutcome outcome = optimizer.step(objective, result.best);
    result.iterations = it;
    result.history.push_back({it, elapsed(), result.best.error.mean, result.best.objective});
    if (outcome == StepOutcome::Converged) {
      const bool converged =
          result.best.statics().converged() && std::isfinite(result.best.objective);
      result.termination = converged ? Termination::Converged : Termination::Failed;
      result.reason = converged ? "stationary after " + std::to_string(it) + " iterations"
                                : "stopped after " + std::to_string(it) +
                                      " iterations at a state that is no converged equilibrium";
      break;
    }
    if (outcome == StepOutcome::OutOfTime) {
      result.termination = Termination::TimeLimit;
      result.reason = "time limit reached";
      break;
    }
    if (outcome == StepOutcome::Stuck) {
      result.termination =
          std::isfinite(result.best.objective) ? Termination::Stuck : Termination::Failed;
      result.reason = std::isfinite(result.best.objective)
                          ? "no acceptable step after " + std::to_string(it) +
                                " iterations (every trial was worse, unsafe or failed statics)"
                          : "no step possible: the objective is not finite (" +
                                std::to_string(result.best.objective) + ")";
      break;
    }
  }
  return result;
}

}  // namespace shapectl
