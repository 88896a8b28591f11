#pragma once
// The obstacles and contacts in the GUI's messages (docs/gui.md, protocol): the scene message's
// "obstacles" and "contact", each state's "contacts". World frame, metres, newtons.
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include <shapectl/contact/obstacle.hpp>
#include <shapectl/contact/obstacle_contact.hpp>
#include <shapectl/contact/self_contact.hpp>
#include <shapectl/robot/robot_model.hpp>

namespace shapectl::server {

// A state lists at most this many contact points (the closest first); "count" is all of them.
inline constexpr std::size_t max_contact_points = 2000;

// [{name, shape, plane: {point, normal} or null, points, edges, triangles, radius, link}, ...];
// link: the name of the robot link (of `robot`) the obstacle moves with, its points then in that
// link's frame; null: the world.
nlohmann::json obstacles_json(const std::vector<Obstacle>& obstacles,
                              const RobotModel* robot = nullptr);

// {count, min_distance (null without a pair within d̂), force_total, by_obstacle: {name:
// {count, force}}, points: [[px, py, pz, fx, fy, fz], ...] (at most `max_points`, the closest
// first), points_total}, and with `self` (self-contact) "self": {count, min_distance, points:
// [[px, py, pz], ...] (each pair's meeting point, the closest first, at most `max_points`),
// points_total}. `obstacles` names the summary's obstacle indices.
nlohmann::json contacts_json(const ContactSummary& summary, const std::vector<Obstacle>& obstacles,
                             std::size_t max_points = max_contact_points,
                             const SelfContactSummary* self = nullptr);

}  // namespace shapectl::server
