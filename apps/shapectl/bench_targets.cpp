#include "bench_targets.hpp"

#include <algorithm>
#include <cmath>

#include <shapectl/contact/obstacle_contact.hpp>

namespace shapectl::cli {

double seconds_between(BenchClock::time_point a, BenchClock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

bool random_goal(const ReducedObjective& objective, const Evaluation& reference, std::mt19937& rng,
                 ShapeTargets& targets, double amplitude, int min_contacts) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Eigen::VectorXd theta = reference.joints();
  for (int j = 0; j < theta.size(); ++j) theta[j] += u(rng);
  const Evaluation goal = objective.evaluate(theta, reference.positions());
  if (!goal.safe()) return false;
  if (min_contacts > 0) {
    const ObstacleContact* contact = objective.object().statics().contact();
    if (!contact || contact->summary(goal.positions()).count < min_contacts) return false;
  }
  const int n = static_cast<int>(goal.positions().size() / 3);
  std::vector<int> nodes(n);
  for (int i = 0; i < n; ++i) nodes[i] = i;
  std::shuffle(nodes.begin(), nodes.end(), rng);
  targets = {};
  for (int k = 0; k < std::min(20, n); ++k) {
    targets.nodes.push_back(nodes[k]);
    targets.positions.push_back(goal.positions().segment<3>(3 * nodes[k]));
  }
  return true;
}

std::optional<std::pair<double, int>> steps_to_1mm(const ReducedObjective& goal,
                                                   const Evaluation& reference, OptimizerKind kind,
                                                   double max_seconds, Evaluation* end) {
  Evaluation current = reference;
  goal.rescore(current);
  auto optimizer = make_optimizer(kind, GradientMethod::Sensitivity);
  const auto t0 = BenchClock::now();
  int it = 0;
  while (current.error.mean >= 1e-3 && it < 200 &&
         seconds_between(t0, BenchClock::now()) < max_seconds) {
    if (optimizer->step(goal, current) != StepOutcome::Improved) break;
    ++it;
  }
  const double seconds = seconds_between(t0, BenchClock::now());
  const bool reached = current.error.mean < 1e-3;
  if (end) *end = std::move(current);
  if (!reached) return std::nullopt;
  return std::pair{seconds, it};
}

}  // namespace shapectl::cli
