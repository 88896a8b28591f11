#pragma once
// A scene file rewritten with new values: `shapectl calibrate` writes the scene it read with the
// fitted material, grip offsets and object pose. Everything else stays as the user wrote it (key
// order, the mesh given as a box or a file, comments-free JSON as read), and relative paths are
// rewritten for the new file's directory, so the result is a complete scene every command
// accepts.
#include <filesystem>

#include <nlohmann/json.hpp>

#include <shapectl/sim/scene.hpp>

namespace shapectl {

// The scene file `source` (already accepted by load_scene) with `scene`'s material (in the
// form the file used: youngs_modulus/poisson_ratio or mu/kappa; and density), each grip's
// offset ("offset": {"position", "rpy"}; none when it is the identity) and the object's pose
// ("object.pose", written only when it differs from the file's), its paths made relative to
// `out`'s directory (obstacle mesh files included; obstacles and contact are written as read).
nlohmann::ordered_json scene_json_with_values(const std::filesystem::path& source,
                                              const Scene& scene, const std::filesystem::path& out);

}  // namespace shapectl
