#include <shapectl/control/optimize.hpp>

#include <chrono>

namespace shapectl {

OptimizeResult optimize(ReducedObjective& objective, Optimizer& optimizer, Evaluation start,
                        const OptimizeOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  OptimizeResult result;
  result.best = std::move(start);
  result.history.push_back({0, 0.0, result.best.error.mean, result.best.objective});
  optimizer.reset();
  for (int it = 1;; ++it) {
    if (it > options.max_iterations) {
      result.reason = "iteration limit (" + std::to_string(options.max_iterations) + ") reached";
      break;
    }
    if (elapsed() > options.max_seconds) {
      result.reason = "time limit reached";
      break;
    }
    const StepOutcome outcome = optimizer.step(objective, result.best);
    result.iterations = it;
    result.history.push_back({it, elapsed(), result.best.error.mean, result.best.objective});
    if (outcome == StepOutcome::Converged) {
      result.converged = result.best.statics.converged();
      result.reason = "stationary after " + std::to_string(it) + " iterations";
      break;
    }
    if (outcome == StepOutcome::Stuck) {
      result.reason = "no acceptable step after " + std::to_string(it) +
                      " iterations (every trial was worse, unsafe or failed statics)";
      break;
    }
  }
  return result;
}

}  // namespace shapectl
