// Depth images as a calibration source (docs/calibration.md, "Depth images"): 16-bit PNGs of
// the clamped bar, read through an observations file, fit as the same points given as point
// cloud files do.
#include <shapectl/calib/calibration.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include <shapectl/calib/depth_png.hpp>
#include <shapectl/calib/npy_header.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "calib/depth_views.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

// An (N, 3) float64 .npy point cloud.
std::string npy_cloud(const std::vector<Vec3>& points) {
  std::string out = npy_header_bytes("<f8", {points.size(), 3});
  for (const Vec3& p : points) out.append(reinterpret_cast<const char*>(p.data()), 24);
  return out;
}

// The clamped bar 1.5× stiffer than the model (50 kPa) and its clamp 3 mm and 2° off, seen by
// two depth cameras (three frames: the first camera twice), 10 % flying pixels; written as
// 16-bit PNGs (0.1 mm a unit) and as the clouds their pixels back-project to.
TEST(DepthCalibration, DepthImagesFitAsTheSamePointsGivenAsACloudDo) {
  Scene model = load_scene(test::source_path("scenes/foam_bar_clamped.json"));
  model.material = material_from_youngs(5e4, 0.3, model.material.density);
  Scene truth = model;
  truth.material = material_from_youngs(7.5e4, 0.3, model.material.density);
  truth.T_world_object = Eigen::Translation3d(0.003 * Vec3(1, -1, 1).normalized()) *
                         Eigen::AngleAxisd(2 * M_PI / 180, Vec3(1, 2, -1).normalized());
  Positions x = truth.world_rest_positions();
  ASSERT_TRUE(ObjectStatics(truth).solve(x).converged());

  test::DepthCamera behind = test::bar_camera();
  behind.pose = test::look_at(Vec3(-0.03, 0.3, 0.3), Vec3(0, 0, -0.02));
  const std::vector<test::DepthCamera> cameras = {test::bar_camera(), test::bar_camera(), behind};
  const double scale = 1e-4, sigma = 0.0003;
  const AlignedBox crop{Vec3(-0.2, -0.1, -0.15), Vec3(0.2, 0.1, 0.1)};
  test::TempDir dir;
  nlohmann::json depth_frames = nlohmann::json::array(), cloud_frames = depth_frames;
  std::mt19937 rng(31);
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    const test::DepthCamera& c = cameras[k];
    const DepthPixels pixels =
        pixels_from_depth(test::seen_depth(c, *model.object_mesh, x, sigma, 0.1, rng), scale);
    const std::string png = "depth" + std::to_string(k) + ".png";
    dir.write(png, depth_png_bytes(pixels));
    nlohmann::json depth = test::depth_image_json(c, png, scale);
    depth["crop"] = {{"box", {{"min", vec3_json(crop.min)}, {"max", vec3_json(crop.max)}}}};
    depth["camera"] = k < 2 ? 0 : 1;
    depth_frames.push_back({{"depth_image", depth}, {"sigma", sigma}});
    std::vector<Vec3> cloud;
    for (const Vec3& p : back_project(depth_from_pixels(pixels, scale), c.intrinsics, c.pose))
      if (crop.contains(p)) cloud.push_back(p);
    const std::string npy = "cloud" + std::to_string(k) + ".npy";
    dir.write(npy, npy_cloud(cloud));
    cloud_frames.push_back({{"points_file", npy}, {"sigma", sigma}});
  }
  const ObservationContext context{.node_count = model.object_mesh->node_count(),
                                   .mesh = model.object_mesh.get()};
  const Observations from_depth =
      load_observations(dir.write("depth.json", nlohmann::json{{"frames", depth_frames}}.dump()),
                        context);
  const Observations from_cloud =
      load_observations(dir.write("cloud.json", nlohmann::json{{"frames", cloud_frames}}.dump()),
                        context);
  EXPECT_EQ(camera_count(from_depth), 2);
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    ASSERT_EQ(from_depth.frames[k].points.size(), from_cloud.frames[k].points.size());
    EXPECT_GT(from_depth.frames[k].points.size(), 2000u);
    // The same points but for the pose's round trip through roll, pitch and yaw.
    for (std::size_t i = 0; i < from_cloud.frames[k].points.size(); ++i)
      ASSERT_LT((from_depth.frames[k].points[i] - from_cloud.frames[k].points[i]).norm(), 1e-12);
  }

  const FitSelection fit = parse_fit_selection("youngs_modulus,object_pose");
  const CalibrationResult depth = calibrate(model, from_depth, fit);
  const CalibrationResult cloud = calibrate(model, from_cloud, fit);
  ASSERT_TRUE(depth.converged) << depth.reason;
  ASSERT_TRUE(cloud.converged) << cloud.reason;
  ASSERT_EQ(depth.parameters.size(), cloud.parameters.size());
  for (std::size_t i = 0; i < depth.parameters.size(); ++i) {
    const FittedParameter &a = depth.parameters[i], &b = cloud.parameters[i];
    EXPECT_GT(b.standard_deviation, 0) << b.name;
    EXPECT_LE(std::abs(a.fitted - b.fitted), b.standard_deviation) << a.name;
  }
  EXPECT_NEAR(depth.fitted.youngs_modulus / 7.5e4, 1, 0.05);
  EXPECT_LT((depth.fitted.object_pose.translation() - truth.T_world_object.translation()).norm(),
            0.001);
}

}  // namespace
}  // namespace shapectl
