// The `shapectl calibrate` contract: a calibrated scene every command accepts, a report, and
// bad observations named.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <random>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/model_parameters.hpp>
#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/scene_io/scene_writer.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

const std::filesystem::path kCantilever = test::source_path("scenes/yumi_cantilever.json");

// OBS.json of a "real" cantilever 1.8× stiffer and gripped 3 mm off, 15 markers at 3 poses.
nlohmann::json synthetic_observations(const Scene& model) {
  Scene truth = model;
  truth.material = material_from_youngs(1.8 * youngs_modulus_of(model.material),
                                        poisson_ratio_of(model.material), model.material.density);
  truth.grips[0].offset.translation() = Vec3(0.003, 0, -0.001);
  const GrippedObject world(truth);
  const auto names = model.robot->model->active_joint_names();
  SimulatedCamera camera;
  for (int node = 3; node < world.node_count(); node += 28) camera.marker_nodes.push_back(node);
  std::mt19937 rng(3);
  nlohmann::json frames = nlohmann::json::array();
  for (double swing : {0.0, 0.15, -0.1}) {
    Eigen::VectorXd joints = model.robot->reference_joints;
    joints[0] += swing, joints[6] += 2 * swing;
    const ObservationFrame f =
        camera.observe(world.mesh(), equilibrium_along_path(world, joints).positions(), joints,
                       rng);
    nlohmann::json frame = {{"joints", nlohmann::json::object()},
                            {"markers", nlohmann::json::array()},
                            {"sigma", f.sigma}};
    for (std::size_t j = 0; j < names.size(); ++j) frame["joints"][names[j]] = joints[j];
    for (const ObservedMarker& m : f.markers)
      frame["markers"].push_back({{"node", m.node}, {"position", vec3_json(m.position)}});
    frames.push_back(frame);
  }
  return {{"frames", frames}};
}

class CalibrateCli : public ::testing::Test {
 protected:
  TempDir dir;
  Scene model = load_scene(kCantilever);
  std::filesystem::path observations = dir.write("obs.json", synthetic_observations(model).dump());
  std::string out = (dir.path() / "calibrated.json").string();
  std::string report = (dir.path() / "report.json").string();
};

TEST_F(CalibrateCli, WritesASceneEveryCommandAcceptsAndAReport) {
  const auto run = run_cli({"calibrate", kCantilever.string(), "--observations",
                            observations.string(), "--out", out, "--report", report});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Scene calibrated = load_scene(out);  // paths rebased into the temp dir still resolve
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  // The truth within 4 reported standard deviations (the library's tests hold the accuracy).
  const double E_true = 1.8 * youngs_modulus_of(model.material);
  EXPECT_NEAR(youngs_modulus_of(calibrated.material), E_true,
              4 * r["parameters"][0]["standard_deviation"].get<double>());
  EXPECT_NEAR(r["parameters"][0]["fitted"].get<double>(), youngs_modulus_of(calibrated.material),
              1e-6 * E_true);
  EXPECT_LT((calibrated.grips[0].offset.translation() - Vec3(0.003, 0, -0.001)).norm(), 0.0005);
  EXPECT_TRUE(r["converged"].get<bool>());
  EXPECT_EQ(r["parameters"].size(), 1u + 6u);
  EXPECT_GT(r["parameters"][0]["standard_deviation"].get<double>(), 0);
  EXPECT_EQ(r["frames"].size(), 3u);
  EXPECT_LT(r["rms_after"].get<double>(), r["rms_before"].get<double>());
  const auto statics = run_cli({"statics", out, "--out", (dir.path() / "statics.json").string()});
  EXPECT_EQ(statics.exit_code, 0) << statics.err;
}

TEST_F(CalibrateCli, StiffnessAndDensityTogetherAreReportedNotIdentifiable) {
  const auto run =
      run_cli({"calibrate", kCantilever.string(), "--observations", observations.string(), "--out",
               out, "--report", report, "--fit", "youngs_modulus,density"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("not identifiable"), std::string::npos) << run.err;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  ASSERT_EQ(r["identifiability"].size(), 1u);
  EXPECT_EQ(r["identifiability"][0]["held_at_initial_value"], "density");
  EXPECT_TRUE(r["parameters"][1]["standard_deviation"].is_null());
}

TEST_F(CalibrateCli, BadObservationsExitOneNamingTheField) {
  nlohmann::json good = nlohmann::json::parse(test::read_text(observations));
  struct Case {
    const char* what;
    std::function<void(nlohmann::json&)> spoil;
    const char* field;
  };
  const std::vector<Case> cases = {
      {"unknown node", [](nlohmann::json& o) { o["frames"][1]["markers"][0]["node"] = 100000; },
       "frames[1].markers[0].node"},
      {"non-finite", [](nlohmann::json& o) { o["frames"][0]["markers"][2]["position"][1] = "nan"; },
       "frames[0].markers[2].position"},
      {"empty frames", [](nlohmann::json& o) { o["frames"] = nlohmann::json::array(); }, "frames"},
      {"joint missing", [](nlohmann::json& o) { o["frames"][2]["joints"].erase("yumi_joint_3_l"); },
       "yumi_joint_3_l"},
      {"joint unknown", [](nlohmann::json& o) { o["frames"][2]["joints"]["elbow"] = 0.1; },
       "elbow"},
      {"unreadable points file",
       [](nlohmann::json& o) { o["frames"][0]["points_file"] = "missing.ply"; }, "missing.ply"},
  };
  for (const Case& c : cases) {
    nlohmann::json bad = good;
    c.spoil(bad);
    const auto file = dir.write("bad.json", bad.dump());
    const auto run =
        run_cli({"calibrate", kCantilever.string(), "--observations", file.string(), "--out", out});
    EXPECT_EQ(run.exit_code, 1) << c.what << ": " << run.err;
    EXPECT_NE(run.err.find(c.field), std::string::npos) << c.what << ": " << run.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.what << ": nothing written";
  }
}

}  // namespace
}  // namespace shapectl
