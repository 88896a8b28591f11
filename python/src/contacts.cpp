// Results' contacts with the scene's obstacles, as RESULT.json's "contacts" (docs/contact.md).
#include <cmath>

#include "bindings.hpp"

namespace shapectl::python {

std::optional<ContactsResult> contacts_at(const ObstacleContact* contact, const Positions& x) {
  if (!contact) return std::nullopt;
  ContactsResult out{contact->summary(x), {}};
  for (const Obstacle& o : contact->obstacles()) out.obstacle_names.push_back(o.name);
  return out;
}

py::object contacts_dict(const std::optional<ContactsResult>& contacts) {
  if (!contacts) return py::none();
  const ContactSummary& s = contacts->summary;
  py::dict by_obstacle;
  for (std::size_t k = 0; k < s.by_obstacle.size(); ++k) {
    py::dict one;
    one["count"] = s.by_obstacle[k].count;
    one["force"] = Eigen::Vector3d(s.by_obstacle[k].force);
    by_obstacle[py::str(contacts->obstacle_names[k])] = one;
  }
  py::dict out;
  out["count"] = s.count;
  out["min_distance"] =
      std::isfinite(s.min_distance) ? py::object(py::float_(s.min_distance)) : py::none();
  out["force_total"] = Eigen::Vector3d(s.force_total);
  out["by_obstacle"] = by_obstacle;
  out["stiffness"] = s.stiffness;
  return out;
}

}  // namespace shapectl::python
