#include <shapectl/calib/depth_image_file.hpp>

#include <string>

#include <shapectl/calib/depth_npy.hpp>
#include <shapectl/calib/depth_png.hpp>
#include <shapectl/calib/point_cloud_file.hpp>
#include <shapectl/io/ascii_case.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/scene_io/scene_file.hpp>  // read_box, read_pose

namespace shapectl {

namespace {

PinholeIntrinsics read_intrinsics(const JsonInput& j) {
  if (!j.is_object()) j.fail("an object {\"fx\", \"fy\", \"cx\", \"cy\"} (pixels)");
  j.expect_only({"fx", "fy", "cx", "cy"});
  return {j.at("fx").positive(), j.at("fy").positive(), j.at("cx").number(), j.at("cy").number()};
}

// The image's depths, m: a 16-bit PNG needs its scale, a float array is in metres unless given.
DepthImage read_image_file(const JsonInput& field, const JsonInput& depth) {
  const std::string name = field.string();
  if (name.empty()) field.fail("a file name (.png or .npy)");
  const std::filesystem::path file = field.directory() / name;
  const std::string extension = lowercase_extension(file);
  if (extension != ".png" && extension != ".npy")
    field.fail("a .png (16-bit grayscale) or .npy (2-D float) file");
  if (extension == ".png" && !depth.has("scale"))
    depth.fail_problem("missing \"scale\" (m per unit of the PNG's values, e.g. 0.001)");
  const double scale = depth.has("scale") ? depth.at("scale").positive() : 1;
  try {
    const bool png = extension == ".png";
    const std::string bytes =
        read_input_file(file, png ? max_depth_png_bytes : max_depth_npy_bytes, "depth image");
    if (png) return depth_from_pixels(read_depth_png(file.string(), bytes), scale);
    return read_depth_npy(file.string(), bytes, scale);
  } catch (const InputError& e) {
    field.fail_problem(std::string("cannot read the depth image: ") + e.what());
  }
}

}  // namespace

DepthImageObservation read_depth_image(const JsonInput& j) {
  if (!j.is_object()) j.fail("an object {\"file\", \"intrinsics\", \"camera_pose\", ...}");
  j.expect_only({"file", "scale", "intrinsics", "camera_pose", "crop", "stride", "camera"});
  const PinholeIntrinsics intrinsics = read_intrinsics(j.at("intrinsics"));
  const JsonInput pose = j.at("camera_pose");
  // Unlike an object's pose, a camera's has no natural default (rpy 0 looks straight up).
  if (!pose.has("position") || !pose.has("rpy"))
    pose.fail("{\"position\": [x, y, z], \"rpy\": [roll, pitch, yaw]}, both given");
  const Eigen::Isometry3d T_world_camera = read_pose(pose);
  const int stride = j.has("stride") ? static_cast<int>(j.at("stride").integer_in(1, 1000)) : 1;
  DepthImageObservation out;
  out.camera.index =
      j.has("camera") ? static_cast<int>(j.at("camera").integer_in(0, max_cameras - 1)) : 0;
  out.camera.position = T_world_camera.translation();
  std::optional<AlignedBox> crop;
  if (j.has("crop")) {
    j.at("crop").expect_only({"box"});
    crop = read_box(j.at("crop").at("box"));
  }
  const DepthImage image = read_image_file(j.at("file"), j);
  for (const Vec3& p : back_project(image, intrinsics, T_world_camera, stride))
    if (!crop || crop->contains(p)) out.points.push_back(p);
  if (out.points.size() > max_point_cloud_points)
    j.fail_problem(std::to_string(out.points.size()) + " points, more than the limit of " +
                   std::to_string(max_point_cloud_points) + " (crop it, or a larger stride)");
  for (std::size_t i = 0; i < out.points.size(); ++i)
    if (!(out.points[i].norm() <= max_observation_distance))
      j.fail_problem("point " + std::to_string(i) + " lies more than " +
                     std::to_string(max_observation_distance) +
                     " m from the origin: is the scale right?");
  return out;
}

}  // namespace shapectl
