// The `shapectl solve` and robot `statics` contracts on the bundled YuMi scenes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <sstream>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::run_cli;
using test::TempDir;

const std::string kBar = test::source_path("scenes/yumi_bar.json").string();
const std::string kFrame = test::source_path("scenes/yumi_frame.json").string();

nlohmann::json run_json(const std::vector<std::string>& args, const std::filesystem::path& out) {
  const auto run = run_cli(args);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return nlohmann::json::parse(test::read_text(out));
}

TEST(SolveCli, ReachesTargetsTakenFromAnotherConfiguration) {
  TempDir dir;
  // The shape at other joint angles (read back from `statics --joints`)...
  const auto reference = run_json({"statics", kBar, "--out", (dir.path() / "ref.json").string()},
                                  dir.path() / "ref.json");
  nlohmann::json joints = reference["joints"];
  joints["yumi_joint_1_l"] = joints["yumi_joint_1_l"].get<double>() + 0.12;
  joints["yumi_joint_2_r"] = joints["yumi_joint_2_r"].get<double>() - 0.1;
  joints["yumi_joint_6_l"] = joints["yumi_joint_6_l"].get<double>() + 0.2;
  const auto joints_file = dir.write("joints.json", nlohmann::json{{"joints", joints}}.dump());
  const auto goal = run_json({"statics", kBar, "--joints", joints_file.string(), "--out",
                              (dir.path() / "goal.json").string()},
                             dir.path() / "goal.json");
  ASSERT_TRUE(goal["converged"].get<bool>());
  EXPECT_EQ(goal["tools"].size(), 2u);
  // ... gives targets for every 17th node.
  nlohmann::json targets = nlohmann::json::array();
  for (int i = 0; i < 425; i += 17)
    targets.push_back({{"node", i}, {"position", goal["positions"][i]}});
  const auto targets_file = dir.write("targets.json", nlohmann::json{{"targets", targets}}.dump());
  const auto out = dir.path() / "solve.json";
  const auto result =
      run_json({"solve", kBar, "--targets", targets_file.string(), "--out", out.string()}, out);
  EXPECT_LT(result["error_mean"].get<double>(), 1e-3);
  EXPECT_GE(result["min_clearance"].get<double>(), 0.0);
  EXPECT_TRUE(result["limit_violations"].empty());
  EXPECT_EQ(result["joints"].size(), 14u);
  EXPECT_EQ(result["positions"].size(), 425u);
  EXPECT_GE(result["history"].size(), 2u);
  EXPECT_GT(result["history"][0]["error_mean"].get<double>(), 3e-3);
  EXPECT_GT(result["timing"]["statics_solves"].get<int>(), 0);
  EXPECT_GT(result["timing"]["gradient_seconds"].get<double>(), 0);
  EXPECT_EQ(result["status"],
            result["error_max"].get<double>() <= 1e-3 ? "reached" : "best effort");
  // A tolerance tighter than the error reached says best effort, with why in words.
  const auto strict = dir.path() / "strict.json";
  const auto tight = run_json({"solve", kBar, "--targets", targets_file.string(), "--out",
                               strict.string(), "--tolerance", "1e-9"},
                              strict);
  EXPECT_EQ(tight["status"], "best effort");
  EXPECT_EQ(tight["tolerance"], 1e-9);
  EXPECT_TRUE(tight["unreachable"].is_array());
  EXPECT_FALSE(tight["status_reason"].get<std::string>().empty());
}

TEST(SolveCli, ASolveResultIsAcceptedAsJointsByStatics) {
  TempDir dir;
  const auto reference = run_json({"statics", kBar, "--out", (dir.path() / "ref.json").string()},
                                  dir.path() / "ref.json");
  nlohmann::json targets = nlohmann::json::array();
  for (int i = 0; i < 425; i += 53) {
    nlohmann::json p = reference["positions"][i];
    p[2] = p[2].get<double>() + 0.01;  // lift the bar by 1 cm
    targets.push_back({{"node", i}, {"position", p}});
  }
  const auto targets_file = dir.write("targets.json", nlohmann::json{{"targets", targets}}.dump());
  const auto solved = dir.path() / "solve.json";
  const auto vtu = dir.path() / "solve.vtu";
  const auto result = run_json({"solve", kBar, "--targets", targets_file.string(), "--out",
                                solved.string(), "--vtu", vtu.string()},
                               solved);
  // solve --vtu: the deformed mesh at the best joints, the result's positions exactly.
  const std::string vtu_text = test::read_text(vtu);
  EXPECT_NE(vtu_text.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(vtu_text.find("NumberOfPoints=\"425\""), std::string::npos);
  EXPECT_NE(vtu_text.find("NumberOfCells=\"1536\""), std::string::npos);
  {
    const std::size_t points = vtu_text.find("<Points>");
    ASSERT_NE(points, std::string::npos);
    std::istringstream in(
        vtu_text.substr(vtu_text.find('>', vtu_text.find("<DataArray", points)) + 1));
    double x = 0, y = 0, z = 0;
    in >> x >> y >> z;
    EXPECT_EQ(x, result["positions"][0][0].get<double>());
    EXPECT_EQ(z, result["positions"][0][2].get<double>());
  }
  // Its joints reproduce its shape.
  const auto again = run_json({"statics", kBar, "--joints", solved.string(), "--out",
                               (dir.path() / "again.json").string()},
                              dir.path() / "again.json");
  ASSERT_TRUE(again["converged"].get<bool>());
  EXPECT_EQ(again["joints"], result["joints"]);
  double largest = 0;
  for (std::size_t i = 0; i < 425; ++i)
    for (std::size_t d = 0; d < 3; ++d)
      largest = std::max(largest, std::abs(again["positions"][i][d].get<double>() -
                                           result["positions"][i][d].get<double>()));
  EXPECT_LT(largest, 1e-6);
  // A hand-written joints file keeps its typo check.
  const auto typo = dir.write("typo.json", R"({"joints": {}, "jionts": {}})");
  const auto bad = run_cli(
      {"statics", kBar, "--joints", typo.string(), "--out", (dir.path() / "x.json").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("jionts"), std::string::npos) << bad.err;
}

// Issue 36 item 11: targets written in mm. Read as metres they lie hundreds of metres away, past
// anything the robot reaches: refused at once (exit 1, nothing optimized or written). With
// "units": "mm" the same file is the reachable shape it describes, and solve reaches it.
TEST(SolveCli, TargetsInMillimetresNeedUnitsAndAreRefusedBeyondReachWithout) {
  TempDir dir;
  nlohmann::json joints = {{"yumi_joint_1_l", -0.02}, {"yumi_joint_1_r", 0.13}};
  const auto joints_file = dir.write("joints.json", nlohmann::json{{"joints", joints}}.dump());
  const auto goal = run_json({"statics", kBar, "--joints", joints_file.string(), "--out",
                              (dir.path() / "goal.json").string()},
                             dir.path() / "goal.json");
  nlohmann::json targets = nlohmann::json::array();
  for (int i = 0; i < 425; i += 53) {
    nlohmann::json mm = nlohmann::json::array();
    for (int d = 0; d < 3; ++d) mm.push_back(1e3 * goal["positions"][i][d].get<double>());
    targets.push_back({{"node", i}, {"position", mm}});
  }
  const auto out = dir.path() / "solve.json";
  const auto in_metres = dir.write("metres.json", nlohmann::json{{"targets", targets}}.dump());
  const auto refused =
      run_cli({"solve", kBar, "--targets", in_metres.string(), "--out", out.string()});
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_NE(refused.err.find(in_metres.string() + ": targets[0]: target "), std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("; the robot reaches at most "), std::string::npos) << refused.err;
  EXPECT_EQ(refused.err.find("solve: "), std::string::npos) << refused.err;  // no optimizing
  EXPECT_FALSE(std::filesystem::exists(out));

  const auto in_mm =
      dir.write("mm.json", nlohmann::json{{"units", "mm"}, {"targets", targets}}.dump());
  const auto result =
      run_json({"solve", kBar, "--targets", in_mm.string(), "--out", out.string()}, out);
  EXPECT_LT(result["error_mean"].get<double>(), 1e-3);
  EXPECT_NEAR(result["targets"][1]["position"][2].get<double>(),
              goal["positions"][53][2].get<double>(), 1e-12);  // read back in metres
  const auto bad_units = dir.write("cubits.json", R"({"units": "cubit", "targets": []})");
  const auto wrong =
      run_cli({"solve", kBar, "--targets", bad_units.string(), "--out", out.string()});
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find(bad_units.string() + ": units: expected \"m\", \"cm\" or \"mm\", got "),
            std::string::npos)
      << wrong.err;
}

TEST(SolveCli, CentreLineIsFollowedOnTheBar) {
  TempDir dir;
  // A gentle arc through the bar's current ends (y = ±0.16), bulging up by 3 cm.
  nlohmann::json line = nlohmann::json::array();
  for (int k = 0; k <= 10; ++k) {
    const double t = k / 10.0, y = 0.16 - 0.32 * t;
    line.push_back({0.3905, y, 0.2553 + 0.03 * std::sin(M_PI * t)});
  }
  const auto targets = dir.write("line.json", nlohmann::json{{"centerline", line}}.dump());
  const auto out = dir.path() / "solve.json";
  const auto result = run_json({"solve", kBar, "--targets", targets.string(), "--out", out.string(),
                                "--max-iterations", "30"},
                               out);
  EXPECT_LT(result["error_mean"].get<double>(),
            result["history"][0]["error_mean"].get<double>() / 3);
  EXPECT_GE(result["targets"].size(), 10u);
}

TEST(SolveCli, BadTargetsAreBadInput) {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"targets": [{"node": 425, "position": [0, 0, 0]}]})",
       "targets[0].node: expected a whole number from 0 to 424"},
      {R"({"targets": []})", "targets: expected a non-empty list of targets"},
      {R"({"targets": [{"node": 1, "position": [0, 0]}]})",
       "targets[0].position: expected an array of 3 numbers"},
      {R"({"centerline": [[0, 0, 0]]})",
       "centerline: expected a polyline of at least 2 distinct points"},
      {R"({"target": []})", "target: unknown key"},
  };
  for (const auto& [text, message] : cases) {
    const auto file = dir.write("bad.json", text);
    const auto run = run_cli(
        {"solve", kBar, "--targets", file.string(), "--out", (dir.path() / "r.json").string()});
    EXPECT_EQ(run.exit_code, 1) << text;
    EXPECT_NE(run.err.find("bad.json: " + message), std::string::npos) << run.err;
  }
}

TEST(SolveCli, MaxSecondsReachesIntoTheStaticsAtTheStart) {
  // A budget far shorter than the statics at the reference joints: the solve stops inside
  // them, says why, exits 2 (a solver failure) and writes nothing (no equilibrium, no result).
  TempDir dir;
  const auto targets =
      dir.write("t.json", R"({"targets": [{"node": 0, "position": [0.3, 0, 0.3]}]})");
  const auto out = dir.path() / "r.json";
  const auto run = run_cli({"solve", kBar, "--targets", targets.string(), "--out", out.string(),
                            "--max-seconds", "1e-6"});
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("stopped (time limit)"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--max-seconds reached"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(SolveCli, ARunCutShortByItsLimitSaysSoInsteadOfALocalMinimum) {
  // One iteration cannot bring node 0 ten centimetres up: best effort, and the reason is the
  // iteration limit, not "a local minimum".
  TempDir dir;
  const auto targets =
      dir.write("t.json", R"({"targets": [{"node": 0, "position": [0.25, 0.05, 0.35]}]})");
  const auto out = dir.path() / "r.json";
  const nlohmann::json r = run_json({"solve", kBar, "--targets", targets.string(), "--out",
                                     out.string(), "--max-iterations", "1"},
                                    out);
  EXPECT_EQ(r["termination"], "iteration limit");
  EXPECT_EQ(r["status"], "best effort");
  const std::string why = r["status_reason"];
  EXPECT_TRUE(r["unreachable"].empty());
  EXPECT_EQ(why.find("local minimum"), std::string::npos) << why;
  EXPECT_NE(why.find("stopped by the iteration limit"), std::string::npos) << why;
}

TEST(SolveCli, CentreLineOnAnObjectThatIsNotBarLikeIsBadInput) {
  TempDir dir;
  const auto file = dir.write("line.json", R"({"centerline": [[0.3, 0, 0.3], [0.4, 0, 0.3]]})");
  const auto run = run_cli(
      {"solve", kFrame, "--targets", file.string(), "--out", (dir.path() / "r.json").string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("line.json: centerline: expected an object that is bar-like"),
            std::string::npos)
      << run.err;
}

// Issue 10: a centre-line of points within 1e-12 m gave NaN targets and exit 0 with nulls.
TEST(SolveCli, DegenerateCentreLineIsBadInputNamingTheCentreLine) {
  TempDir dir;
  const auto out = dir.write("r.json", "precious");
  for (const std::string line :
       {R"({"centerline": [[0.39, 0, 0.25], [0.39, 1e-13, 0.25], [0.39, 0, 0.2500000000001]]})",
        R"({"centerline": [[0.39, 0, 0.25], [0.39, 0.00001, 0.25]]})"}) {
    const auto file = dir.write("line.json", line);
    const auto run = run_cli({"solve", kBar, "--targets", file.string(), "--out", out.string()});
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find(
                  "line.json: centerline: expected a polyline of at least 2 distinct points"),
              std::string::npos)
        << run.err;
    EXPECT_EQ(test::read_text(out), "precious");
  }
}

// Issue 10: a target at 1e155 said "converged" with error_mean null; −1e300 crashed L-BFGS.
TEST(SolveCli, AbsurdTargetsAreRefusedWithoutCrashOrNull) {
  TempDir dir;
  const auto out = dir.write("r.json", "precious");
  for (const std::string optimizer : {"gauss-newton", "lbfgs"})
    for (const std::string position :
         {"[1e155, 0, 0.2]", "[0.4, -1e300, 0.2]", "[0.4, 0, 1000.5]"}) {
      const auto file = dir.write(
          "t.json",
          R"({"targets": [{"node": 3, "position": [0.4, 0, 0.25]}, {"node": 7, "position": )" +
              position + "}]}");
      const auto run = run_cli({"solve", kBar, "--targets", file.string(), "--out", out.string(),
                                "--optimizer", optimizer, "--max-iterations", "3"});
      EXPECT_EQ(run.exit_code, 1) << run.err;
      EXPECT_NE(run.err.find("t.json: targets[1].position: expected a"), std::string::npos)
          << run.err;
      EXPECT_NE(run.err.find("1000 m"), std::string::npos) << run.err;
      EXPECT_EQ(test::read_text(out), "precious");
    }
}

TEST(StaticsCli, UnknownJointInJointsFileIsNamed) {
  TempDir dir;
  const auto file = dir.write("j.json", R"({"joints": {"yumi_joint_9_l": 0.1}})");
  const auto run = run_cli(
      {"statics", kBar, "--joints", file.string(), "--out", (dir.path() / "r.json").string()});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("j.json: joints.yumi_joint_9_l: unknown joint in "), std::string::npos)
      << run.err;
  // A joint of the robot that the scene does not optimise (it fixes the fingers).
  const auto finger = dir.write("f.json", R"({"joints": {"gripper_l_joint": 0.01}})");
  const auto fixed = run_cli(
      {"statics", kBar, "--joints", finger.string(), "--out", (dir.path() / "r.json").string()});
  EXPECT_EQ(fixed.exit_code, 1);
  EXPECT_NE(fixed.err.find("f.json: joints.gripper_l_joint: not an active joint of the robot"),
            std::string::npos)
      << fixed.err;
}

}  // namespace
}  // namespace shapectl
