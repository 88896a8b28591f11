#pragma once
// The points of a .xyz text file.
#include <string>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// `text` is the whole file, `name` names it in messages. One point a line: x y z, then any
// further columns (colour, normal, intensity: ignored); '#' starts a comment, blank lines are
// skipped. At most max_point_cloud_points points. Throws InputError "name:line: ...": fewer
// than 3 values, a value that is not a finite number, too many points.
std::vector<Vec3> read_xyz_points(const std::string& name, std::string text);

}  // namespace shapectl
