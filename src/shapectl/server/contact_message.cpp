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

nlohmann::json contacts_json(const ContactSummary& summary, const std::vector<Obstacle>& obstacles,
                             std::size_t max_points) {
  nlohmann::json by_obstacle = nlohmann::json::object();
  for (std::size_t k = 0; k < summary.by_obstacle.size() && k < obstacles.size(); ++k)
    by_obstacle[obstacles[k].name] = {{"count", summary.by_obstacle[k].count},
                                      {"force", vec3_json(summary.by_obstacle[k].force)}};
  // The closest pairs carry the largest forces: those are kept when the list is cut.
  const std::vector<ContactPoint>& all = summary.points;
  std::vector<std::size_t> order(all.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::size_t shown = std::min(max_points, order.size());
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
                    [&](std::size_t a, std::size_t b) {
                      return all[a].distance < all[b].distance;
                    });
  nlohmann::json points = nlohmann::json::array();
  for (std::size_t k = 0; k < shown; ++k) {
    const ContactPoint& c = all[order[k]];
    points.push_back(
        {c.point.x(), c.point.y(), c.point.z(), c.force.x(), c.force.y(), c.force.z()});
  }
  return {{"count", summary.count},
          {"min_distance", std::isfinite(summary.min_distance)
                               ? nlohmann::json(summary.min_distance)
                               : nlohmann::json(nullptr)},
          {"force_total", vec3_json(summary.force_total)},
          {"by_obstacle", by_obstacle},
          {"points", points},
          {"points_total", all.size()}};
}

}  // namespace shapectl::server
