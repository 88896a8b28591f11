#include <shapectl/control/targets_file.hpp>

#include <set>

#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/io/length_units.hpp>

namespace shapectl {

namespace {
constexpr double max_distance = 1e3;  // m: targets are in reach of a robot, not kilometres off
}  // namespace

TargetsInput read_targets(const JsonInput& json, int node_count) {
  json.expect_only({"targets", "centerline", "units"});
  TargetsInput in;
  if (json.has("targets") == json.has("centerline"))
    json.fail("an object with either \"targets\" or \"centerline\"");
  std::string unit = "m";
  double scale = 1;  // file coordinates to metres
  if (json.has("units")) {
    unit = json.at("units").string();
    const auto factor = metres_per_unit(unit);
    if (!factor) json.at("units").fail("\"m\", \"cm\" or \"mm\"");
    scale = *factor;
  }
  // A point in the file's unit, bounded there (the message speaks that unit), in metres.
  auto point = [&](const JsonInput& p) {
    return Vec3(scale * p.vec3_within(max_distance / scale, "a point", unit));
  };
  if (json.has("targets")) {
    const JsonInput list = json.at("targets");
    if (list.size() == 0) list.fail("a non-empty list of targets");
    if (list.size() > max_target_count)
      list.fail_problem(std::to_string(list.size()) + " targets, more than the limit of " +
                        std::to_string(max_target_count));
    std::set<int> seen;
    for (std::size_t k = 0; k < list.size(); ++k) {
      const JsonInput t = list.at(k);
      t.expect_only({"node", "position"});
      const int node = static_cast<int>(t.at("node").integer_in(0, node_count - 1));
      if (!seen.insert(node).second) t.at("node").fail("a node without another target");
      in.targets.nodes.push_back(node);
      in.targets.positions.push_back(point(t.at("position")));
    }
  } else {
    const JsonInput list = json.at("centerline");
    if (list.size() > max_centerline_points)
      list.fail_problem(std::to_string(list.size()) + " points, more than the limit of " +
                        std::to_string(max_centerline_points));
    for (std::size_t k = 0; k < list.size(); ++k) in.centerline.push_back(point(list.at(k)));
    double length = 0;
    for (std::size_t k = 1; k < in.centerline.size(); ++k)
      length += (in.centerline[k] - in.centerline[k - 1]).norm();
    if (in.centerline.size() < 2 || !(length > 0))
      list.fail("a polyline of at least 2 distinct points");
  }
  return in;
}

TargetsInput load_targets(const std::filesystem::path& file, int node_count) {
  return read_targets(JsonInput::load(file), node_count);
}

nlohmann::json targets_json(const ShapeTargets& targets) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t k = 0; k < targets.nodes.size(); ++k)
    list.push_back({{"node", targets.nodes[k]}, {"position", vec3_json(targets.positions[k])}});
  return list;
}

}  // namespace shapectl
