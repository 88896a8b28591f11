// The `shapectl calibrate` contract: a calibrated scene every command accepts, a report, and
// bad observations named; for a robot's scene and for one held by fixed nodes alone.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <random>
#include <sstream>

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/calib/model_parameters.hpp>
#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/io/json_eigen.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/scene_io/scene_file.hpp>
#include <shapectl/scene_io/scene_writer.hpp>
#include <shapectl/sim/object_statics.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

const std::filesystem::path kCantilever = test::source_path("scenes/yumi_cantilever.json");
const std::filesystem::path kClamped = test::source_path("scenes/foam_bar_clamped.json");

// One frame of OBS.json: its markers and σ, and its joints by `names` (none without a robot).
nlohmann::json frame_json(const ObservationFrame& f, const std::vector<std::string>& names) {
  nlohmann::json frame = {{"markers", nlohmann::json::array()}, {"sigma", f.sigma}};
  for (std::size_t j = 0; j < names.size(); ++j) frame["joints"][names[j]] = f.joints[j];
  for (const ObservedMarker& m : f.markers)
    frame["markers"].push_back({{"node", m.node}, {"position", vec3_json(m.position)}});
  return frame;
}

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
    frames.push_back(
        frame_json(camera.observe(world.mesh(), equilibrium_along_path(world, joints).positions(),
                                  joints, rng),
                   names));
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
  // The object's pose was not fitted: it stays as the file wrote it.
  EXPECT_EQ(nlohmann::json::parse(test::read_text(out))["object"]["pose"],
            nlohmann::json::parse(test::read_text(kCantilever))["object"]["pose"]);
  const auto statics = run_cli({"statics", out, "--out", (dir.path() / "statics.json").string()});
  EXPECT_EQ(statics.exit_code, 0) << statics.err;
}

TEST_F(CalibrateCli, StiffnessAndDensityTogetherAreReportedNotIdentifiable) {
  const auto run =
      run_cli({"calibrate", kCantilever.string(), "--observations", observations.string(), "--out",
               out, "--report", report, "--fit", "youngs_modulus,density"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("not determined by these observations"), std::string::npos) << run.err;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  ASSERT_EQ(r["identifiability"].size(), 1u);
  EXPECT_EQ(r["identifiability"][0]["held_at_initial_value"], "density");
  EXPECT_TRUE(r["parameters"][1]["standard_deviation"].is_null());
  EXPECT_EQ(r["parameters"][1]["verdict"], "not determined");
  EXPECT_EQ(r["parameters"][1]["trades_off_with"], nlohmann::json::array({"youngs_modulus"}));
  EXPECT_NE(r["parameters"][1]["suggestion"].get<std::string>().find("hanging weight"),
            std::string::npos);
  EXPECT_NE(run.err.find("hanging weight"), std::string::npos) << run.err;
}

// Issue 35: each value with its prior (physical units) and verdict; the defaults' priors on the
// grip offsets (5 mm, 3°), none on the material.
TEST_F(CalibrateCli, TheReportGivesPriorsAndVerdicts) {
  const auto run = run_cli({"calibrate", kCantilever.string(), "--observations",
                            observations.string(), "--out", out, "--report", report});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  EXPECT_TRUE(r["parameters"][0]["prior"].is_null());
  EXPECT_EQ(r["parameters"][0]["verdict"], "determined");
  EXPECT_EQ(r["parameters"][1]["name"], "grip_offsets.left.x");
  EXPECT_NEAR(r["parameters"][1]["prior"].get<double>(), 0.005, 1e-15);
  EXPECT_NEAR(r["parameters"][4]["prior"].get<double>(), 3 * M_PI / 180, 1e-15);
  EXPECT_FALSE(r["parameters"][1]["implausible"].get<bool>());
  EXPECT_EQ(r["implausible"], nlohmann::json::array());
  EXPECT_NE(run.err.find("(determined; prior σ 0.005 m)"), std::string::npos) << run.err;
  // --prior changes them, --prior off removes them.
  const auto changed =
      run_cli({"calibrate", kCantilever.string(), "--observations", observations.string(), "--out",
               out, "--report", report, "--prior", "grip_offsets=2mm/1deg,youngs_modulus=50%"});
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  const nlohmann::json c = nlohmann::json::parse(test::read_text(report));
  EXPECT_NEAR(c["parameters"][0]["prior"].get<double>(), 0.5 * youngs_modulus_of(model.material),
              1e-6);
  EXPECT_NEAR(c["parameters"][1]["prior"].get<double>(), 0.002, 1e-15);
  const auto off =
      run_cli({"calibrate", kCantilever.string(), "--observations", observations.string(), "--out",
               out, "--report", report, "--prior", "off"});
  ASSERT_EQ(off.exit_code, 0) << off.err;
  for (const auto& p : nlohmann::json::parse(test::read_text(report))["parameters"])
    EXPECT_TRUE(p["prior"].is_null()) << p["name"];
}

TEST_F(CalibrateCli, BadPriorsAndBoundsExitOneNamingTheOptionAndTheEntry) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--prior", "object_pose.rotation=2furlongs"},
      {"--prior", "grip_offsets=5mm"},
      {"--prior", "stiffness=50%"},
      {"--prior", "youngs_modulus=-5%"},
      {"--bounds", "youngs_modulus=1e8:1e3"},
      {"--bounds", "poisson_ratio=0.1:0.9"},
      {"--bounds", "density=x:2000"},
      {"--bounds", "youngs_modulus=1e6:1e8"},  // the scene's 200 kPa outside
  };
  for (const auto& [option, entry] : cases) {
    const auto run = run_cli({"calibrate", kCantilever.string(), "--observations",
                              observations.string(), "--out", out, option, entry});
    EXPECT_EQ(run.exit_code, 1) << option << " " << entry << ": " << run.err;
    EXPECT_NE(run.err.find(option + ": "), std::string::npos) << run.err;
    const std::string name = entry.substr(0, entry.find('='));
    EXPECT_NE(run.err.find(name), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << entry;
  }
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
      // Issue 32: calibrate walked the model from the reference joints towards it for hours.
      {"joint at a million radians",
       [](nlohmann::json& o) { o["frames"][1]["joints"]["yumi_joint_3_l"] = 1e6; },
       "frames[1].joints.yumi_joint_3_l: expected a value within the joint's limits"},
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

// Issue 32: `calibrate` on any input ends within its deadline. Thousands of frames at a pose
// within the limits but away from the reference joints: each is walked to from there, and the
// fit's first evaluation alone would take minutes.
TEST_F(CalibrateCli, AHostileInputEndsWithinMaxSeconds) {
  const nlohmann::json good = nlohmann::json::parse(test::read_text(observations));
  nlohmann::json many = {{"frames", nlohmann::json::array()}};
  for (int k = 0; k < 3000; ++k) many["frames"].push_back(good["frames"][1]);
  const auto file = dir.write("many.json", many.dump());
  const auto started = std::chrono::steady_clock::now();
  const auto run = run_cli({"calibrate", kCantilever.string(), "--observations", file.string(),
                            "--out", out, "--max-seconds", "2"});
  const std::chrono::duration<double> took = std::chrono::steady_clock::now() - started;
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("time limit"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--max-seconds reached"), std::string::npos) << run.err;
  EXPECT_LT(took.count(), 2.5) << "the process's start and reading the files come on top";
  EXPECT_FALSE(std::filesystem::exists(out)) << "stopped before a first fit: nothing written";
}

TEST_F(CalibrateCli, MaxSecondsMustBeAPositiveNumber) {
  for (const char* seconds : {"0", "-1", "nan"}) {
    const auto run = run_cli({"calibrate", kCantilever.string(), "--observations",
                              observations.string(), "--out", out, "--max-seconds", seconds});
    EXPECT_EQ(run.exit_code, 1) << seconds << ": " << run.err;
    EXPECT_NE(run.err.find("--max-seconds: expected a positive number of seconds"),
              std::string::npos)
        << run.err;
  }
}

// A scene without a robot: the clamped foam bar's stiffness and clamp pose, the fitted pose in
// a scene every command accepts, and frames that must not name joints.

// The "real" bar: 1.5× stiffer, its clamp 3 mm and 2° off the scene's placement.
Scene true_clamped_bar(const Scene& model) {
  Scene truth = model;
  truth.material = material_from_youngs(1.5 * youngs_modulus_of(model.material),
                                        poisson_ratio_of(model.material), model.material.density);
  truth.T_world_object =
      Eigen::Translation3d(0.003, 0, 0) * Eigen::AngleAxisd(2 * M_PI / 180, Vec3::UnitY());
  return truth;
}

// OBS.json of the clamped bar: two frames of the true equilibrium, 15 markers each, no joints.
nlohmann::json clamped_observations(const Scene& truth) {
  Positions x = truth.world_rest_positions();
  const ObjectStatics statics(truth);
  EXPECT_TRUE(statics.solve(x).converged());
  SimulatedCamera camera;
  for (int node = 3; node < statics.mesh().node_count(); node += 28)
    camera.marker_nodes.push_back(node);
  std::mt19937 rng(5);
  nlohmann::json frames = nlohmann::json::array();
  for (int k = 0; k < 2; ++k)
    frames.push_back(frame_json(camera.observe(statics.mesh(), x, Eigen::VectorXd(), rng), {}));
  return {{"frames", frames}};
}

class CalibrateFixedCli : public ::testing::Test {
 protected:
  TempDir dir;
  Scene model = load_scene(kClamped);
  Scene truth = true_clamped_bar(model);
  std::filesystem::path observations = dir.write("obs.json", clamped_observations(truth).dump());
  std::string out = (dir.path() / "calibrated.json").string();
  std::string report = (dir.path() / "report.json").string();
};

TEST_F(CalibrateFixedCli, FitsStiffnessAndClampPoseIntoASceneEveryCommandAccepts) {
  const auto run = run_cli({"calibrate", kClamped.string(), "--observations", observations.string(),
                            "--out", out, "--report", report});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  ASSERT_EQ(r["parameters"].size(), 1u + 6u);  // the default for a clamped scene: E and pose
  EXPECT_EQ(r["parameters"][1]["name"], "object_pose.x");
  EXPECT_TRUE(r["converged"].get<bool>());
  EXPECT_EQ(r["frames"].size(), 2u);
  const Scene calibrated = load_scene(out);
  EXPECT_NEAR(youngs_modulus_of(calibrated.material), youngs_modulus_of(truth.material),
              4 * r["parameters"][0]["standard_deviation"].get<double>());
  EXPECT_LT((calibrated.T_world_object.translation() - truth.T_world_object.translation()).norm(),
            0.0005);
  EXPECT_LT(Eigen::AngleAxisd(calibrated.T_world_object.linear() *
                              truth.T_world_object.linear().transpose())
                .angle(),
            0.5 * M_PI / 180);
  EXPECT_TRUE(nlohmann::json::parse(test::read_text(out))["object"].contains("pose"));
  const auto statics = run_cli({"statics", out, "--out", (dir.path() / "statics.json").string()});
  EXPECT_EQ(statics.exit_code, 0) << statics.err;
}

// Issue 35: every form of a path (a bare name, ./, absolute, ..) for the scene, the observations
// and the outputs, run from where the form makes sense; the scene's mesh file named relative to
// it, and "joints": {} in the frames of this scene without a robot. Each calibrated scene loads
// from anywhere (its mesh path rebased), and nothing exits 3.
TEST_F(CalibrateFixedCli, EveryFormOfAPathIsAccepted) {
  namespace fs = std::filesystem;
  const TetMesh& mesh = *model.object_mesh;
  std::ostringstream node, ele;  // the scene's box as a TetGen pair, node order kept
  node.precision(17);
  node << mesh.node_count() << " 3 0 0\n";
  for (int i = 0; i < mesh.node_count(); ++i) {
    const Vec3& p = mesh.rest_positions()[i];
    node << i << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  ele << mesh.tet_count() << " 4 0\n";
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const auto& n = mesh.tets()[t].nodes;
    ele << t << " " << n[0] << " " << n[1] << " " << n[2] << " " << n[3] << "\n";
  }
  dir.write("meshes/bar.node", node.str());
  dir.write("meshes/bar.ele", ele.str());
  nlohmann::json scene = nlohmann::json::parse(test::read_text(kClamped));
  scene["object"]["mesh"] = "../meshes/bar.ele";
  dir.write("work/scene.json", scene.dump());
  nlohmann::json obs = nlohmann::json::parse(test::read_text(observations));
  for (auto& frame : obs["frames"]) frame["joints"] = nlohmann::json::object();
  dir.write("work/obs.json", obs.dump());
  dir.write("work/sub/.keep", "");
  const fs::path work = dir.path() / "work";
  struct Form {
    const char* name;
    fs::path cwd;
    std::string scene, observations, out, report;
  };
  const std::vector<Form> forms = {
      {"bare names", work, "scene.json", "obs.json", "bare.json", "bare_report.json"},
      {"./", work, "./scene.json", "./obs.json", "./dot.json", "./dot_report.json"},
      {"absolute", dir.path(), (work / "scene.json").string(), (work / "obs.json").string(),
       (dir.path() / "absolute.json").string(), (dir.path() / "absolute_report.json").string()},
      {"..", work / "sub", "../scene.json", "../obs.json", "../../up.json", "../up_report.json"}};
  for (const Form& f : forms) {
    const auto run = run_cli({"calibrate", f.scene, "--observations", f.observations, "--out",
                              f.out, "--report", f.report},
                             f.cwd);
    EXPECT_EQ(run.exit_code, 0) << f.name << ": " << run.err;
    const fs::path written = fs::path(f.out).is_absolute() ? fs::path(f.out) : f.cwd / f.out;
    EXPECT_NO_THROW(load_scene(written)) << f.name;
    EXPECT_TRUE(
        fs::exists(fs::path(f.report).is_absolute() ? fs::path(f.report) : f.cwd / f.report))
        << f.name;
  }
}

// Issue 35: Young's modulus held at the scene's value (the real bar 4x softer), the clamp's pose
// fitted: it tilts to absorb the sag, and the tilt beyond 3 prior σ is flagged (exit 0).
TEST_F(CalibrateFixedCli, APoseBeyondItsPriorIsFlaggedImplausible) {
  Scene softer = model;
  softer.material = material_from_youngs(youngs_modulus_of(model.material) / 4,
                                         poisson_ratio_of(model.material), model.material.density);
  const auto obs = dir.write("softer.json", clamped_observations(softer).dump());
  const auto run = run_cli({"calibrate", kClamped.string(), "--observations", obs.string(), "--out",
                            out, "--report", report, "--fit", "object_pose"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  ASSERT_FALSE(r["implausible"].empty()) << run.err;
  const std::string name = r["implausible"][0];
  EXPECT_NE(run.err.find("warning: " + name), std::string::npos) << run.err;
  for (const auto& p : r["parameters"]) {
    if (p["name"] == name) {
      EXPECT_TRUE(p["implausible"].get<bool>());
    }
  }
  // Without priors there is nothing to judge it by.
  const auto off = run_cli({"calibrate", kClamped.string(), "--observations", obs.string(), "--out",
                            out, "--report", report, "--fit", "object_pose", "--prior", "off"});
  ASSERT_EQ(off.exit_code, 0) << off.err;
  EXPECT_TRUE(nlohmann::json::parse(test::read_text(report))["implausible"].empty());
}

TEST_F(CalibrateFixedCli, AFrameWithJointsExitsOneNamingTheField) {
  nlohmann::json bad = nlohmann::json::parse(test::read_text(observations));
  bad["frames"][1]["joints"] = {{"yumi_joint_1_l", 0.1}};
  const auto file = dir.write("bad.json", bad.dump());
  const auto run =
      run_cli({"calibrate", kClamped.string(), "--observations", file.string(), "--out", out});
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("bad.json: frames[1].joints: the scene has no robot"), std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(CalibrateFixedCli, ParametersTheSceneDoesNotHaveExitOneNamingFit) {
  const auto grips = run_cli({"calibrate", kClamped.string(), "--observations",
                              observations.string(), "--out", out, "--fit", "grip_offsets"});
  EXPECT_EQ(grips.exit_code, 1) << grips.err;
  EXPECT_NE(grips.err.find("--fit: grip_offsets: the scene has no grips"), std::string::npos)
      << grips.err;
  const std::string gripped = test::source_path("scenes/yumi_bar.json").string();
  const auto pose = run_cli({"calibrate", gripped, "--observations", observations.string(), "--out",
                             out, "--fit", "youngs_modulus,object_pose"});
  EXPECT_EQ(pose.exit_code, 1) << pose.err;
  EXPECT_NE(pose.err.find("--fit: object_pose: the object is held by the robot's grips alone"),
            std::string::npos)
      << pose.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// Issue 35, load series: OBS.json frames of the clamped bar (truly 20 % softer and 25 % denser)
// unloaded and with 7 g and 14 g hung from its free end, each frame's "loads" given: stiffness
// and density both determined and written; the same frames without their loads leave density
// not determined, and the report says to add loads.
nlohmann::json load_series_observations(const Scene& truth, bool with_loads) {
  SimulatedCamera camera;
  for (int node = 3; node < truth.object_mesh->node_count(); node += 28)
    camera.marker_nodes.push_back(node);
  camera.sigma = 0.0005;
  std::mt19937 rng(7);
  nlohmann::json frames = nlohmann::json::array();
  for (double grams : {0.0, 7.0, 14.0}) {
    const nlohmann::json loads =
        nlohmann::json::array({{{"box", {{"min", {0.159, -1, -1}}, {"max", {1, 1, 1}}}},
                                {"force", {0, 0, -grams * 1e-3 * 9.81}}}});
    Scene loaded = truth;
    loaded.loads = read_loads(JsonInput(loads, "loads"), *truth.object_mesh);
    Positions x = loaded.world_rest_positions();
    const ObjectStatics statics(loaded);
    EXPECT_TRUE(statics.solve(x).converged());
    nlohmann::json frame =
        frame_json(camera.observe(statics.mesh(), x, Eigen::VectorXd(), rng), {});
    frame["sigma"] = camera.sigma;
    if (with_loads) frame["loads"] = loads;
    frames.push_back(frame);
  }
  return {{"frames", frames}};
}

TEST_F(CalibrateFixedCli, PerFrameLoadsSeparateStiffnessAndDensity) {
  Scene real = model;
  real.material =
      material_from_youngs(0.8 * youngs_modulus_of(model.material),
                           poisson_ratio_of(model.material), 1.25 * model.material.density);
  const auto series = dir.write("series.json", load_series_observations(real, true).dump());
  const auto run = run_cli({"calibrate", kClamped.string(), "--observations", series.string(),
                            "--out", out, "--report", report, "--fit", "youngs_modulus,density"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(report));
  ASSERT_EQ(r["parameters"].size(), 2u);
  for (const auto& p : r["parameters"]) EXPECT_EQ(p["verdict"], "determined") << p.dump();
  const Scene calibrated = load_scene(out);
  EXPECT_NEAR(youngs_modulus_of(calibrated.material) / youngs_modulus_of(real.material), 1, 0.03);
  EXPECT_NEAR(calibrated.material.density / real.material.density, 1, 0.03);

  const auto unloaded = dir.write("unloaded.json", load_series_observations(real, false).dump());
  const auto blind = run_cli({"calibrate", kClamped.string(), "--observations", unloaded.string(),
                              "--out", out, "--report", report, "--fit", "youngs_modulus,density"});
  ASSERT_EQ(blind.exit_code, 0) << blind.err;
  const nlohmann::json b = nlohmann::json::parse(test::read_text(report));
  EXPECT_EQ(b["parameters"][1]["verdict"], "not determined");
  EXPECT_NE(b["parameters"][1]["suggestion"].get<std::string>().find("\"loads\""),
            std::string::npos);
  EXPECT_NE(blind.err.find("hung from the free end"), std::string::npos) << blind.err;
}

TEST_F(CalibrateFixedCli, BadPerFrameLoadsAndRegionsExitOneNamingTheField) {
  nlohmann::json bad = nlohmann::json::parse(test::read_text(observations));
  bad["frames"][1]["loads"] = {{{"nodes", {3}}, {"force", {0, 0, "heavy"}}}};
  const auto file = dir.write("bad.json", bad.dump());
  const auto run =
      run_cli({"calibrate", kClamped.string(), "--observations", file.string(), "--out", out});
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("bad.json: frames[1].loads[0].force[2]: expected a number"),
            std::string::npos)
      << run.err;
  bad["frames"][1]["loads"] = {
      {{"box", {{"min", {5, 5, 5}}, {"max", {6, 6, 6}}}}, {"force", {0, 0, -1}}}};
  const auto nowhere = dir.write("nowhere.json", bad.dump());
  const auto empty =
      run_cli({"calibrate", kClamped.string(), "--observations", nowhere.string(), "--out", out});
  EXPECT_EQ(empty.exit_code, 1) << empty.err;
  EXPECT_NE(empty.err.find("nowhere.json: frames[1].loads[0].box: expected a box around at least "
                           "one node"),
            std::string::npos)
      << empty.err;
  const auto region =
      run_cli({"calibrate", kClamped.string(), "--observations", observations.string(), "--out",
               out, "--fit", "regions[1].youngs_modulus"});
  EXPECT_EQ(region.exit_code, 1) << region.err;
  EXPECT_NE(region.err.find("--fit: regions[1].youngs_modulus: the scene has no \"regions\""),
            std::string::npos)
      << region.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// Issue 35: "priors" and "bounds" in the observations file, --prior's and --bounds' syntax;
// the command line's entries win; bad ones name the file and the field.
TEST_F(CalibrateFixedCli, PriorsAndBoundsInTheObservationsFileUnderTheCommandLine) {
  nlohmann::json obs = nlohmann::json::parse(test::read_text(observations));
  obs["priors"] = "youngs_modulus=10%,object_pose=5mm/1deg";
  obs["bounds"] = "youngs_modulus=1e4:1e7";
  const auto file = dir.write("with_priors.json", obs.dump());
  const auto prior_of = [&](const std::vector<std::string>& extra, std::size_t k) {
    std::vector<std::string> args = {"calibrate",      kClamped.string(),
                                     "--observations", file.string(),
                                     "--out",          out,
                                     "--report",       report};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto run = run_cli(args);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return nlohmann::json::parse(test::read_text(report))["parameters"][k]["prior"].get<double>();
  };
  const double E = youngs_modulus_of(model.material);
  EXPECT_NEAR(prior_of({}, 0), 0.1 * E, 1e-9 * E);
  EXPECT_NEAR(prior_of({}, 1), 0.005, 1e-12);  // object_pose.x
  EXPECT_NEAR(prior_of({"--prior", "youngs_modulus=20%"}, 0), 0.2 * E, 1e-9 * E);
  EXPECT_NEAR(prior_of({"--prior", "youngs_modulus=20%"}, 1), 0.005, 1e-12);  // the file's

  obs["bounds"] = "youngs_modulus=1e6:1e8";  // the scene's 200 kPa outside
  const auto outside = dir.write("outside.json", obs.dump());
  const auto run =
      run_cli({"calibrate", kClamped.string(), "--observations", outside.string(), "--out", out});
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("outside.json: bounds: youngs_modulus: the scene's value"),
            std::string::npos)
      << run.err;
  const auto widened = run_cli({"calibrate", kClamped.string(), "--observations", outside.string(),
                                "--out", out, "--bounds", "youngs_modulus=1e3:1e8"});
  EXPECT_EQ(widened.exit_code, 0) << widened.err;
  std::filesystem::remove(out);

  obs.erase("bounds");
  obs["priors"] = "stiffness=5%";
  const auto unknown = dir.write("unknown.json", obs.dump());
  const auto bad =
      run_cli({"calibrate", kClamped.string(), "--observations", unknown.string(), "--out", out});
  EXPECT_EQ(bad.exit_code, 1) << bad.err;
  EXPECT_NE(bad.err.find("unknown.json: priors: \"stiffness=5%\": unknown name"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace shapectl
