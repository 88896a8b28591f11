// Results' contacts with the scene's obstacles and the object's with itself, as RESULT.json's
// "contacts" (docs/contact.md).
#include <cmath>
#include <limits>

#include "bindings.hpp"

namespace shapectl::python {

std::optional<ContactsResult> contacts_at(const ObstacleContact* contact, const SelfContact* self,
                                          const Positions& x) {
  if (!contact && !self) return std::nullopt;
  ContactsResult out;
  out.summary.min_distance = std::numeric_limits<double>::infinity();
  if (contact) {
    out.summary = contact->summary(x);
    for (const Obstacle& o : contact->obstacles()) out.obstacle_names.push_back(o.name);
  }
  if (self) out.self = self->summary(x);
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
  if (const auto& self = contacts->self) {
    py::dict one;
    one["count"] = self->count;
    one["min_distance"] =
        std::isfinite(self->min_distance) ? py::object(py::float_(self->min_distance)) : py::none();
    out["self"] = one;
  }
  if (!contacts->obstacle_names.empty()) out["stiffness"] = s.stiffness;
  return out;
}

}  // namespace shapectl::python
