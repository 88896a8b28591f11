#pragma once
// Runs an optimizer to convergence (or an iteration/time budget) from a start state.
#include <functional>
#include <string_view>
#include <vector>

#include <shapectl/control/optimizer.hpp>

namespace shapectl {

struct OptimizeOptions {
  int max_iterations = 100;
  // Checked before every statics trial and gradient (Optimizer::out_of_time): the run ends at
  // most one statics solve or gradient after it.
  double max_seconds = 60;
  // Seconds since the start; empty: the steady clock. Tests pass a simulated clock.
  std::function<double()> clock = nullptr;
};

struct HistoryEntry {
  int iteration = 0;
  double time = 0;  // seconds since the start
  double error_mean = 0;
  double objective = 0;
};

// Why a run ended.
enum class Termination {
  Converged,       // stationary at a converged equilibrium with a finite objective
  IterationLimit,  // max_iterations done
  TimeLimit,       // max_seconds spent
  Stuck,           // no acceptable step (every trial worse, unsafe or failed statics)
  Failed,          // no step possible or the state is no converged equilibrium
};
const char* to_string(Termination termination);
bool parse(std::string_view name, Termination* termination);

struct OptimizeResult {
  Evaluation best;  // the state reached (safe if the start was)
  Termination termination = Termination::Failed;
  std::string reason;  // the termination in words, with numbers
  bool converged() const { return termination == Termination::Converged; }
  int iterations = 0;
  std::vector<HistoryEntry> history;  // entry 0 is the start
};

OptimizeResult optimize(const ReducedObjective& objective, Optimizer& optimizer, Evaluation start,
                        const OptimizeOptions& options);

}  // namespace shapectl
