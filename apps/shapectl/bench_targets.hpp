#pragma once
// What the rows of `shapectl bench` share: random reachable goals, the time an optimizer takes
// from the reference shape to a mean error below 1 mm, and percentiles.
#include <chrono>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include <shapectl/control/optimizer.hpp>

namespace shapectl::cli {

using BenchClock = std::chrono::steady_clock;
double seconds_between(BenchClock::time_point a, BenchClock::time_point b);

// The p-quantile (0..1, nearest rank) of v; NaN for none.
double percentile(std::vector<double> v, double p);

// A safe, reachable goal: random joints within ±amplitude rad of the reference, their
// equilibrium, 20 of its nodes as targets. False when that equilibrium is not safe, or when it
// has fewer than min_contacts object–obstacle contacts (a goal resting on the table).
bool random_goal(const ReducedObjective& objective, const Evaluation& reference, std::mt19937& rng,
                 ShapeTargets& targets, double amplitude = 0.15, int min_contacts = 0);

// Optimizer steps from the reference shape until the mean error to `goal`'s targets is below
// 1 mm (at most 200 steps or max_seconds): the seconds and steps it took, or none if it stopped
// short. `end` (optional) receives the last state either way.
std::optional<std::pair<double, int>> steps_to_1mm(const ReducedObjective& goal,
                                                   const Evaluation& reference, OptimizerKind kind,
                                                   double max_seconds = 10,
                                                   Evaluation* end = nullptr);

}  // namespace shapectl::cli
