#include "closed_loop_options.hpp"

#include <shapectl/calib/joint_path.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/scene_io/scene_file.hpp>

#include "commands.hpp"

namespace shapectl::cli {

void add_closed_loop_options(CLI::App& cmd, ClosedLoopArgs& args, bool feedback_flag) {
  cmd.add_option("--world", args.world,
                 "WORLD.json: simulate the real object (true material, grip offsets; same mesh) "
                 "with --robot sim; a camera observes markers on the target nodes")
      ->check(CLI::ExistingFile);
  cmd.add_option("--camera-rate", args.camera_rate, "--world: observations per second")
      ->capture_default_str();
  cmd.add_option("--camera-sigma", args.camera_sigma, "--world: measurement noise, m")
      ->capture_default_str();
  cmd.add_option("--camera-points", args.camera_points,
                 "--world: surface points per frame, as a depth camera sees them")
      ->capture_default_str();
  cmd.add_option("--camera-outliers", args.camera_outliers,
                 "--world: fraction of those points that are outliers")
      ->capture_default_str();
  if (feedback_flag)
    cmd.add_flag("--feedback,!--no-feedback", args.feedback,
                 "with observations: model-error feedback on their markers (default) or not");
  cmd.add_option("--trust-region", args.trust_region,
                 "with observations: how far (rad, each joint) what they say may move the joints "
                 "from where the optimizer stopped for the user's last request")
      ->capture_default_str();
  cmd.add_flag("--online-calibration,!--no-online-calibration", args.online_calibration,
               "with observations: re-calibrate --fit in the background (default) or not");
  cmd.add_option("--fit", args.fit, "parameters the online calibration fits")
      ->capture_default_str();
}

SimulatedCamera simulated_camera(const ClosedLoopArgs& args, const std::string& command) {
  if (!(args.camera_rate > 0 && args.camera_rate <= 1000))
    throw InputError(command, "--camera-rate", "0 < rate <= 1000 per second", args.camera_rate);
  if (!(args.camera_sigma >= 0 && args.camera_sigma <= 0.1))
    throw InputError(command, "--camera-sigma", "0 <= sigma <= 0.1 m", args.camera_sigma);
  if (args.camera_points < 0 || args.camera_points > 100'000)
    throw InputError(command, "--camera-points", "0 to 100000 points", args.camera_points);
  if (!(args.camera_outliers >= 0 && args.camera_outliers < 1))
    throw InputError(command, "--camera-outliers", "a fraction in [0, 1)", args.camera_outliers);
  SimulatedCamera camera;
  camera.sigma = args.camera_sigma;
  camera.surface_points = args.camera_points;
  camera.outlier_fraction = args.camera_outliers;
  return camera;
}

double feedback_trust_region(const ClosedLoopArgs& args, const std::string& command) {
  // Past π a box bounds nothing a revolute joint can do.
  if (!(args.trust_region > 0 && args.trust_region <= 3.15))
    throw InputError(command, "--trust-region", "0 < radius <= 3.15 rad", args.trust_region);
  return args.trust_region;
}

OnlineCalibrationOptions online_calibration_options(const ClosedLoopArgs& args,
                                                    const std::string& command) {
  OnlineCalibrationOptions options;
  options.automatic = args.online_calibration;
  try {
    options.fit = parse_fit_selection(args.fit);
  } catch (const std::invalid_argument& e) {
    throw InputError(command, "--fit", e.what());
  }
  return options;
}

std::unique_ptr<SimulatedWorld> simulated_world(const ClosedLoopArgs& args, const Scene& model,
                                                const SimulatedCamera& camera) {
  const Scene world = load_scene(args.world);
  try {
    return std::make_unique<SimulatedWorld>(world, model, camera, args.camera_rate);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.world, "object", e.what());
  } catch (const NoEquilibrium& e) {
    throw SolverFailure(args.world + ": the world's object at the reference joints: " + e.what());
  }
}

}  // namespace shapectl::cli
