#include <shapectl/server/contact_message.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

#include <shapectl/io/json_eigen.hpp>

namespace shapectl::server {

nlohmann::json obstacles_json(const std::vector<Obstacle>& obstacles, const RobotModel* robot) {
  nlohmann::json out = nlohmann::json::array();
  for (const Obstacle& o : obstacles) {
    nlohmann::json plane = nullptr;
    if (o.plane)
      plane = {{"point", vec3_json(o.plane->point)}, {"normal", vec3_json(o.plane->normal)}};
    out.push_back(
        {{"name", o.name},
         {"shape", o.shape},
         {"plane", plane},
         {"points", points_json(o.points)},
         {"edges", o.edges},
         {"triangles", o.triangles},
         {"radius", o.radius},
         {"link", o.link >= 0 && robot
                      ? nlohmann::json(robot->links()[static_cast<std::size_t>(o.link)].name)
                      : nlohmann::json(nullptr)}});
  }
  return out;
}

namespace {

nlohmann::json distance_or_null(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

// The indices of the `count` smallest `distances`, smallest first: the closest pairs carry the
// largest forces, those are kept when a list is cut.
std::vector<std::size_t> closest_first(const std::vector<double>& distances, std::size_t count) {
  std::vector<std::size_t> order(distances.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::size_t shown = std::min(count, order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
                    [&](std::size_t a, std::size_t b) { return distances[a] < distances[b]; });
  order.resize(shown);
  return order;
}

nlohmann::json self_json(const SelfContactSummary& self, std::size_t max_points) {
  nlohmann::json points = nlohmann::json::array();
  for (std::size_t k : closest_first(self.distances, max_points))
    points.push_back(vec3_json(self.points[k]));
  return {{"count", self.count},
          {"min_distance", distance_or_null(self.min_distance)},
          {"points", points},
          {"points_total", self.points.size()}};
}

}  // namespace

nlohmann::json contacts_json(const ContactSummary& summary, const std::vector<Obstacle>& obstacles,
                             std::size_t max_points, const SelfContactSummary* self) {
  nlohmann::json by_obstacle = nlohmann::json::object();
  for (std::size_t k = 0; k < summary.by_obstacle.size() && k < obstacles.size(); ++k)
    by_obstacle[obstacles[k].name] = {{"count", summary.by_obstacle[k].count},
                                      {"force", vec3_json(summary.by_obstacle[k].force)}};
  const std::vector<ContactPoint>& all = summary.points;
  std::vector<double> distances;
  for (const ContactPoint& c : all) distances.push_back(c.distance);
  nlohmann::json points = nlohmann::json::array();
  for (std::size_t k : closest_first(distances, max_points)) {
    const ContactPoint& c = all[k];
    points.push_back(
        {c.point.x(), c.point.y(), c.point.z(), c.force.x(), c.force.y(), c.force.z()});
  }
  nlohmann::json out = {{"count", summary.count},
                        {"min_distance", distance_or_null(summary.min_distance)},
                        {"force_total", vec3_json(summary.force_total)},
                        {"by_obstacle", by_obstacle},
                        {"points", points},
                        {"points_total", all.size()}};
  if (self) out["self"] = self_json(*self, max_points);
  return out;
}

}  // namespace shapectl::server
