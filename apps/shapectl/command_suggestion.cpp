#include "command_suggestion.hpp"

#include <algorithm>
#include <numeric>

namespace shapectl::cli {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // One row of the dynamic programme: row[j] = distance(a[0..i), b[0..j)).
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
    }
  }
  return row[b.size()];
}

std::optional<std::string> nearest_name(std::string_view typed,
                                        const std::vector<std::string>& names) {
  std::vector<std::string> extended;  // "kin" → "kinematics"
  for (const auto& name : names)
    if (!typed.empty() && name.rfind(typed, 0) == 0) extended.push_back(name);
  if (extended.size() == 1) return extended.front();
  std::optional<std::string> best;
  std::size_t best_distance = std::min<std::size_t>(3, (typed.size() + 1) / 2);  // exclusive
  for (const auto& name : names)
    if (const std::size_t d = edit_distance(typed, name); d < best_distance)
      best = name, best_distance = d;
  return best;
}

std::optional<std::string> unknown_command_message(CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return std::nullopt;  // an option: CLI11's to judge
  const std::string typed = argv[1];
  std::vector<std::string> names;
  for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    names.push_back(command->get_name());
  if (std::find(names.begin(), names.end(), typed) != names.end()) return std::nullopt;
  std::string message = "unknown command '" + typed + "'";
  if (const auto near = nearest_name(typed, names)) message += "; did you mean '" + *near + "'?";
  message += " (commands:";
  for (std::size_t k = 0; k < names.size(); ++k) message += (k ? ", " : " ") + names[k];
  return message + ")";
}

}  // namespace shapectl::cli
