// Scene and targets files: bounded sizes, depths and totals, physical ranges, duplicate keys,
// and messages that name the file and the field.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <functional>
#include <string>

#include <shapectl/control/targets_file.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::TempDir;

std::string error_of(const std::function<void()>& f) { return test::input_error_of(f); }

// The clamped bar with `mesh`, `material` and `gravity` replaceable.
std::string bar_scene(
    const std::string& mesh = R"({"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}})",
    const std::string& material = R"({"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40})",
    const std::string& extra = R"("gravity": [0, 0, -9.81])") {
  return R"({"object": {"mesh": )" + mesh + R"(, "material": )" + material + "},\n" + extra +
         R"(, "fixed": {"box": {"min": [-0.17, -1, -1], "max": [-0.15, 1, 1]}}})";
}

// The error of loading `text` as a scene file, with the file's path replaced by "scene.json".
std::string scene_error(const std::string& text) {
  const TempDir dir;
  const auto file = dir.write("scene.json", text);
  std::string message = error_of([&] { load_scene(file); });
  if (message.rfind(file.string(), 0) == 0)
    message = "scene.json" + message.substr(file.string().size());
  return message;
}

TEST(SceneLimits, BoxCellProductIsBoundedNamingTheField) {
  const std::string message =
      scene_error(bar_scene(R"({"box": {"size": [1, 1, 1], "cells": [1000, 1000, 1000]}})"));
  EXPECT_EQ(
      message,
      "scene.json: object.mesh.box.cells: expected at most 166666 cells in all (6 tetrahedra each, "
      "at most 1000000 tetrahedra), got [1000,1000,1000]");
}

TEST(SceneLimits, DegenerateBoxNamesFileAndField) {
  EXPECT_EQ(scene_error(bar_scene(R"({"box": {"size": [1000, 1e-6, 1e-6], "cells": [1, 1, 1]}})")),
            "scene.json: object.mesh.box.size: expected a size whose cells (size / cells) are not "
            "too flat "
            "for tetrahedra, got cells of 1000 x 1e-06 x 1e-06 m");
  // A hole that removes every cell: the box mesh's own message, placed in the scene.
  EXPECT_EQ(
      scene_error(bar_scene(
          R"({"box": {"size": [1, 1, 1], "cells": [1, 1, 1], "hole": {"min": [-1, -1, -1], "max": [1, 1, 1]}}})")),
      "scene.json: object.mesh.box: box mesh: the mesh has no tetrahedra");
}

TEST(SceneLimits, TinyMaxTetVolumeIsRefusedNamingTheField) {
  const TempDir dir;
  std::string cube = "";
  for (int i = 0; i < 8; ++i)
    cube += "v " + std::to_string(i & 1) + " " + std::to_string((i >> 1) & 1) + " " +
            std::to_string((i >> 2) & 1) + "\n";
  cube += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  dir.write("cube.obj", cube);
  const auto file =
      dir.write("scene.json", bar_scene(R"({"file": "cube.obj", "max_tet_volume": 1e-15})"));
  EXPECT_EQ(
      error_of([&] { load_scene(file); })
          .rfind(file.string() +
                     ": object.mesh.max_tet_volume: expected 0 (no bound) or at least 5e-06 m^3",
                 0),
      0u);
}

TEST(SceneLimits, AbsurdNumbersAreRefusedWithTheRange) {
  EXPECT_EQ(scene_error(bar_scene(R"({"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}})",
                                  R"({"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40})",
                                  R"("gravity": [0, 0, 1e300])")),
            "scene.json: gravity: expected a gravity vector of length at most 1000 m/s^2, got "
            "[0,0,1e+300]");
  const std::string box = R"({"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}})";
  EXPECT_EQ(scene_error(
                bar_scene(box, R"({"youngs_modulus": 1e20, "poisson_ratio": 0.3, "density": 40})")),
            "scene.json: object.material.youngs_modulus: expected a number from 1 to 1e+13 Pa, got "
            "1e+20");
  EXPECT_EQ(scene_error(
                bar_scene(box, R"({"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 0})")),
            "scene.json: object.material.density: expected a positive number, got 0");
  EXPECT_EQ(scene_error(
                bar_scene(box, R"({"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 2e5})")),
            "scene.json: object.material.density: expected a number from 0.001 to 100000 kg/m^3, "
            "got 200000.0");
  EXPECT_EQ(scene_error(bar_scene(box, R"({"mu": 1e4, "kappa": 1e30, "density": 40})")),
            "scene.json: object.material.kappa: expected a number from 0.1 to 1e+16 Pa, got 1e+30");
  EXPECT_EQ(
      scene_error(bar_scene(R"({"box": {"size": [1e4, 0.03, 0.03], "cells": [8, 2, 2]}})")),
      "scene.json: object.mesh.box.size[0]: expected a number from 1e-06 to 1000 m, got 10000.0");
  const std::string pose =
      R"({"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}}, "pose": {"position": [1e4, 0, 0]})";
  EXPECT_EQ(scene_error(bar_scene(pose)),
            "scene.json: object.pose.position: expected a position of length at most 1000 m, got "
            "[10000.0,0,0]");
}

TEST(SceneLimits, ResearchRangeMaterialsAreAccepted) {
  const std::string box = R"({"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}})";
  for (const char* material : {R"({"youngs_modulus": 1e2, "poisson_ratio": 0.3, "density": 0.1})",
                               R"({"youngs_modulus": 1e12, "poisson_ratio": 0.45, "density": 2e4})",
                               // nu = 0.5 - 5e-7; kappa 1e14 (0.5 - 5e-13) would not be
                               // resolved under this light object's weight: refused
                               R"({"mu": 1e2, "kappa": 1e8, "density": 1})"}) {
    const TempDir dir;
    EXPECT_NO_THROW(load_scene(dir.write("scene.json", bar_scene(box, material)))) << material;
  }
}

TEST(SceneLimits, DeepAndDuplicatedJsonIsAnInputError) {
  const std::string deep =
      "{\"object\": " + std::string(55'000, '[') + std::string(55'000, ']') + "}";
  EXPECT_EQ(scene_error(deep), "scene.json:1: JSON nested deeper than 64 levels");
  const std::string twice =
      bar_scene(R"({"box": {"size": [0.32, 0.03, 0.03], "cells": [8, 2, 2]}})",
                R"({"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": 40, "density": 4})");
  EXPECT_EQ(scene_error(twice),
            "scene.json: object.material.density: duplicate key (each key may appear once)");
}

TEST(SceneLimits, HugeUnknownKeyGivesABoundedMessage) {
  const std::string key(5'000'000, 'q');
  const std::string message = scene_error("{\"" + key + "\": 1}");
  EXPECT_EQ(message.rfind("scene.json: " + std::string(80, 'q') + "…: unknown key; known: object, ",
                          0),
            0u);
  EXPECT_LT(message.size(), 400u);
}

TEST(SceneLimits, FifoSceneAndMeshAreRefusedWithoutWaiting) {
  const TempDir dir;
  const auto fifo = dir.path() / "scene.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { load_scene(fifo); }), fifo.string() + ": not a regular file (a FIFO)");
  ASSERT_EQ(mkfifo((dir.path() / "bar.msh").c_str(), 0600), 0);
  const auto scene = dir.write("fifo_mesh.json", bar_scene("\"bar.msh\""));
  EXPECT_EQ(error_of([&] { load_scene(scene); }),
            (dir.path() / "bar.msh").string() + ": not a regular file (a FIFO)");
}

TEST(TargetsLimits, OversizeDeepAndLongTargetsAreRefused) {
  const TempDir dir;
  const auto big =
      dir.write("big.json", "{\"centerline\": [" + std::string(max_json_file_bytes, ' ') + "]}");
  EXPECT_EQ(error_of([&] {
              load_targets(big, 10);
            }).rfind(big.string() + ": larger than the 8388608 byte limit for JSON files", 0),
            0u);
  const auto deep = dir.write("deep.json", "{\"targets\": " + std::string(55'000, '[') +
                                               std::string(55'000, ']') + "}");
  EXPECT_EQ(error_of([&] { load_targets(deep, 10); }),
            deep.string() + ":1: JSON nested deeper than 64 levels");
  std::string points = "[0, 0, 0]";
  for (std::size_t k = 0; k < max_centerline_points; ++k) points += ",[0,0,1]";
  const auto line = dir.write("line.json", "{\"centerline\": [" + points + "]}");
  EXPECT_EQ(error_of([&] { load_targets(line, 10); }),
            line.string() + ": centerline: 100001 points, more than the limit of 100000");
  const auto far = dir.write("far.json", R"({"targets": [{"node": 1, "position": [0, 5e3, 0]}]})");
  EXPECT_EQ(
      error_of([&] { load_targets(far, 10); }),
      far.string() +
          ": targets[0].position: expected a point of length at most 1000 m, got [0,5000.0,0]");
}

}  // namespace
}  // namespace shapectl
