#include <shapectl/sim/contact_obstacles.hpp>

#include <algorithm>
#include <map>

namespace shapectl {

std::vector<char> end_effector_links(const RobotModel& robot, int link) {
  int top = link;  // the child of the last active joint above `link`
  for (int l = link; robot.links()[l].parent_joint >= 0;) {
    const Joint& j = robot.joints()[robot.links()[l].parent_joint];
    if (robot.active_index(robot.links()[l].parent_joint) >= 0) {
      top = j.child_link;
      break;
    }
    l = j.parent_link;
  }
  // Joints are in tree order: a link's parent is flagged before it.
  std::vector<char> own(robot.links().size(), 0);
  own[top] = 1;
  for (const Joint& j : robot.joints())
    if (own[j.parent_link]) own[j.child_link] = 1;
  return own;
}

std::vector<Obstacle> contact_obstacles(const Scene& scene) {
  std::vector<Obstacle> out = scene.obstacles;
  if (!scene.robot) return out;
  const RobotModel& robot = *scene.robot->model;
  if (scene.contact.robot && scene.robot->collisions) {
    std::map<int, int> count;
    for (const CollisionSphere& s : scene.robot->collisions->spheres()) {
      Obstacle o =
          make_sphere(robot.links()[s.link].name + " sphere " + std::to_string(++count[s.link]),
                      s.center_link, s.radius);
      o.link = s.link;
      out.push_back(std::move(o));
    }
  }
  for (const Grip& g : scene.grips) {
    const std::vector<char> own =
        end_effector_links(robot, scene.robot->end_effectors[g.end_effector].link);
    for (Obstacle& o : out)
      if (o.link >= 0 && own[o.link]) {
        o.ignored_nodes.insert(o.ignored_nodes.end(), g.nodes.begin(), g.nodes.end());
        std::sort(o.ignored_nodes.begin(), o.ignored_nodes.end());
        o.ignored_nodes.erase(std::unique(o.ignored_nodes.begin(), o.ignored_nodes.end()),
                              o.ignored_nodes.end());
      }
  }
  return out;
}

}  // namespace shapectl
