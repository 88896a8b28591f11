// `shapectl calibrate` with depth images (docs/calibration.md, "Depth images"): a camera's pose
// fitted from 16-bit PNGs, and every bad image or field exits 1 naming the file and the field.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <random>
#include <set>

#include <shapectl/calib/depth_npy.hpp>
#include <shapectl/calib/depth_png.hpp>
#include <shapectl/calib/npy_header.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "calib/depth_views.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;

const std::filesystem::path kClamped = test::source_path("scenes/foam_bar_clamped.json");

// The clamped bar of the scene, seen by test::bar_camera() twice; "depth.png" in `dir`.
class CalibrateDepthCli : public ::testing::Test {
 protected:
  test::TempDir dir;
  nlohmann::json good;
  std::string out = (dir.path() / "calibrated.json").string();

  void SetUp() override {
    const Scene scene = load_scene(kClamped);
    Positions x = scene.world_rest_positions();
    ASSERT_TRUE(ObjectStatics(scene).solve(x).converged());
    const test::DepthCamera c = test::bar_camera();
    std::mt19937 rng(4);
    nlohmann::json frames = nlohmann::json::array();
    for (int k = 0; k < 2; ++k) {
      const std::string png = "depth" + std::to_string(k) + ".png";
      dir.write(png, depth_png_bytes(pixels_from_depth(
                         test::seen_depth(c, *scene.object_mesh, x, 0.0003, 0.1, rng), 1e-4)));
      nlohmann::json depth = test::depth_image_json(c, png, 1e-4);
      depth["stride"] = 2;
      frames.push_back({{"depth_image", depth}, {"sigma", 0.0003}});
    }
    good = {{"frames", frames}};
  }

  test::CliRun calibrate(const nlohmann::json& observations,
                         const std::string& fit = "youngs_modulus,object_pose,camera_poses") {
    const auto file = dir.write("obs.json", observations.dump());
    return run_cli({"calibrate", kClamped.string(), "--observations", file.string(), "--out", out,
                    "--fit", fit, "--report", (dir.path() / "report.json").string()});
  }
};

TEST_F(CalibrateDepthCli, FitsTheCameraPoseWithItsPrior) {
  const auto run = calibrate(good);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(test::read_text(dir.path() / "report.json"));
  ASSERT_EQ(report["parameters"].size(), 1u + 6 + 6);
  EXPECT_EQ(report["parameters"][7]["name"], "cameras[0].pose.x");
  EXPECT_EQ(report["parameters"][7]["prior"], 0.01);
  EXPECT_EQ(report["parameters"][12]["name"], "cameras[0].pose.rz");
  // The scene is the truth here: nothing moves beyond its noise.
  for (const auto& p : report["parameters"]) EXPECT_FALSE(p["implausible"].get<bool>()) << p;
  EXPECT_GT(report["frames"][0]["points"].get<int>(), 500);
  EXPECT_EQ(run.err.find("near the fitted surface"), std::string::npos) << run.err;
  const auto priors = run_cli({"calibrate", kClamped.string(), "--observations",
                               (dir.path() / "obs.json").string(), "--out", out, "--fit",
                               "youngs_modulus,camera_poses", "--prior", "camera_poses=5mm/1deg"});
  EXPECT_EQ(priors.exit_code, 0) << priors.err;
  EXPECT_NE(priors.err.find("cameras[0].pose.x"), std::string::npos) << priors.err;
}

TEST_F(CalibrateDepthCli, BadDepthImagesExitOneNamingTheFileAndTheField) {
  dir.write("text.png", "not an image at all");
  dir.write("ints.npy", npy_header_bytes("<i2", {4, 4}) + std::string(32, '\0'));
  dir.write("cube.npy", npy_header_bytes("<f4", {2, 2, 2}) + std::string(32, '\0'));
  const std::string field = "obs.json: frames[1].depth_image";
  const std::vector<std::pair<std::function<void(nlohmann::json&)>, std::string>> cases = {
      {[](nlohmann::json& d) { d.erase("intrinsics"); }, field + ".intrinsics: missing key"},
      {[](nlohmann::json& d) { d["intrinsics"]["fx"] = -300; },
       field + ".intrinsics.fx: expected a positive number, got -300"},
      {[](nlohmann::json& d) { d["scale"] = 0; },
       field + ".scale: expected a positive number, got 0"},
      {[](nlohmann::json& d) { d.erase("scale"); }, field + ": missing \"scale\""},
      {[](nlohmann::json& d) {
         d["crop"] = {{"box", {{"min", {0, 0, 0}}, {"max", {-1, 1, 1}}}}};
       },
       field + ".crop.box.max: expected a corner not below min in any axis"},
      {[](nlohmann::json& d) { d["file"] = "text.png"; },
       "text.png: expected the PNG signature (not a PNG file)"},
      {[](nlohmann::json& d) { d["file"] = "ints.npy"; },
       "ints.npy: header 'descr': expected '<f4' or '<f8'"},
      {[](nlohmann::json& d) { d["file"] = "cube.npy"; },
       "cube.npy: header 'shape': expected (height, width), got (2, 2, 2)"},
      {[](nlohmann::json& d) { d["file"] = "missing.png"; },
       field + ".file: cannot read the depth image: "},
      {[](nlohmann::json& d) {
         d["camera_pose"]["rpy"] = {0, 0};
       },
       field + ".camera_pose.rpy: "},
      {[](nlohmann::json& d) { d["camera_pose"].erase("rpy"); },
       field + ".camera_pose: expected {\"position\": [x, y, z], \"rpy\": [roll, pitch, yaw]}, "
               "both given"},
  };
  for (const auto& [change, expected] : cases) {
    nlohmann::json bad = good;
    change(bad["frames"][1]["depth_image"]);
    const auto run = calibrate(bad);
    EXPECT_EQ(run.exit_code, 1) << expected << "\n" << run.err;
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
  // Both a cloud and a depth image in one frame; camera poses without a depth image.
  nlohmann::json both = good;
  both["frames"][0]["points"] = {{0, 0, 0}};
  const auto twice = calibrate(both);
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("frames[0]: more than one of"), std::string::npos) << twice.err;
  const nlohmann::json markers = {
      {"frames", {{{"markers", {{{"node", 3}, {"position", {0, 0, 0}}}}}}}}};
  const auto no_camera = calibrate(markers);
  EXPECT_EQ(no_camera.exit_code, 1);
  EXPECT_NE(no_camera.err.find("--fit: camera_poses: no frame has a depth image"),
            std::string::npos)
      << no_camera.err;
}

}  // namespace
TEST_F(CalibrateDepthCli, AFrameMostlyOfBackgroundKeepsItsObjectPointsAndGetsANoteToCropIt) {
  // The bar's surface nodes as a cloud, with four times as many points of a floor 20 cm below
  // it: the median distance lies on the floor, yet the cut-off keeps the bar's points (and only
  // them), and the report says the floor could be cropped.
  const Scene scene = load_scene(kClamped);
  Positions x = scene.world_rest_positions();
  ASSERT_TRUE(ObjectStatics(scene).solve(x).converged());
  std::set<int> surface;
  for (const auto& t : scene.object_mesh->surface_triangles()) surface.insert(t.begin(), t.end());
  nlohmann::json cloud = nlohmann::json::array();
  Vec3 centre = Vec3::Zero();
  for (int i : surface) {
    cloud.push_back(vec3_json(x.segment<3>(3 * i)));
    centre += x.segment<3>(3 * i) / surface.size();
  }
  for (int i = 0; i < 4 * static_cast<int>(surface.size()); ++i)
    cloud.push_back(
        vec3_json(centre + Vec3(0.002 * (i % 100) - 0.1, 0.002 * (i / 100) - 0.1, -0.2)));
  nlohmann::json observations = good;
  observations["frames"].push_back({{"points", cloud}, {"sigma", 0.0003}});
  const auto run = calibrate(observations, "youngs_modulus");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(test::read_text(dir.path() / "report.json"));
  EXPECT_EQ(report["frames"][2]["inlier_points_after"].get<int>(), surface.size());
  EXPECT_LT(report["frames"][2]["rms_after"].get<double>(), 1e-3);
  EXPECT_NE(run.err.find("frames[2]: only "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("\"crop\" box"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("frames[0]: only "), std::string::npos) << run.err;
}

}  // namespace shapectl
