#pragma once
// The closed loop's options, the same for `run` and `serve`: the simulated world and its
// camera, model-error feedback, and the online calibration (docs/calibration.md).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include <shapectl/calib/online_calibration.hpp>
#include <shapectl/calib/simulated_camera.hpp>
#include <shapectl/calib/simulated_world.hpp>

namespace shapectl::cli {

struct ClosedLoopArgs {
  std::string world;             // WORLD.json: the simulated real object
  double camera_rate = 10;       // observations per second
  double camera_sigma = 0.0003;  // m
  int camera_points = 0;         // surface points per frame (a depth camera)
  double camera_outliers = 0;    // fraction of them that are outliers
  bool feedback = true;
  double trust_region = 0.02;  // rad (ControllerOptions::trust_region)
  bool online_calibration = true;
  std::string fit = "youngs_modulus,grip_offsets";
};

// `feedback_flag`: whether --feedback/--no-feedback is offered (`serve` leaves the switch to
// the page).
void add_closed_loop_options(CLI::App& cmd, ClosedLoopArgs& args, bool feedback_flag);
// The world's camera (markers on the target nodes, set by the caller); InputError naming the
// option of `command` that is out of range.
SimulatedCamera simulated_camera(const ClosedLoopArgs& args, const std::string& command);
// --trust-region, checked; InputError naming it when out of range.
double feedback_trust_region(const ClosedLoopArgs& args, const std::string& command);
OnlineCalibrationOptions online_calibration_options(const ClosedLoopArgs& args,
                                                    const std::string& command);
// The world of --world (non-empty) holding `model`'s mesh with its robot: InputError when
// WORLD.json is no such scene, SolverFailure when its object has no equilibrium at the
// reference joints (a world too soft to hold itself up).
std::unique_ptr<SimulatedWorld> simulated_world(const ClosedLoopArgs& args, const Scene& model,
                                                const SimulatedCamera& camera);

}  // namespace shapectl::cli
