// shapectl.calibrate: what `shapectl calibrate` computes, the fields of its REPORT.json and the
// calibrated scene (CALIBRATED.json is its to_dict()).
#include <cmath>

#include <shapectl/calib/calibration.hpp>

#include "bindings.hpp"

namespace shapectl::python {

namespace {

// The library's result with the calibrated scene as Python holds scenes.
struct Calibration : CalibrationResult {
  SceneHandle calibrated;
};

Observations observations_from(const py::handle& in, const Scene& scene) {
  const ObservationContext context{.node_count = scene.object_mesh->node_count(),
                                   .robot = scene.robot ? scene.robot->model.get() : nullptr,
                                   .mesh = scene.object_mesh.get(),
                                   .allow_points_files = true};
  if (py::isinstance<py::dict>(in))
    return read_observations(JsonInput(json_from(in, "observations"), "observations"), context);
  return load_observations(path_from(in, "observations",
                                     "an OBSERVATIONS.json path or a dict of its schema"),
                           context);
}

// "youngs_modulus,grip_offsets" or ["youngs_modulus", "grip_offsets"], checked as --fit.
FitSelection fit_from(const py::handle& fit) {
  std::string list;
  if (py::isinstance<py::str>(fit)) {
    list = py::cast<std::string>(fit);
  } else if (py::isinstance<py::list>(fit) || py::isinstance<py::tuple>(fit)) {
    for (const auto& name : fit) {
      if (!py::isinstance<py::str>(name))
        throw py::type_error("fit: expected a list of parameter names, got one holding a " +
                             std::string(py::str(py::type::of(name).attr("__name__"))));
      if (!list.empty()) list += ',';
      list += py::cast<std::string>(name);
    }
  } else {
    throw py::type_error("fit: expected a str or a list of parameter names, got a " +
                         std::string(py::str(py::type::of(fit).attr("__name__"))));
  }
  try {
    return parse_fit_selection(list);
  } catch (const std::invalid_argument&) {
    throw InputError("fit", "", std::string("a comma-separated list of ") + fit_parameter_names(),
                     list);
  }
}

bool finite(const CalibrationResult& r) {
  bool ok = std::isfinite(r.rms_before) && std::isfinite(r.rms_after) &&
            std::isfinite(r.chi_squared_per_dof);
  for (const FittedParameter& p : r.parameters)
    ok = ok && std::isfinite(p.fitted) && std::isfinite(p.standard_deviation);
  return ok;
}

// prior= and bounds= as the CLI's --prior and --bounds, over the observations' "priors" and
// "bounds"; a bad entry → ValueError naming it.
void priors_and_bounds(const std::string& prior, const std::string& bounds, const Scene& scene,
                       const FitSelection& fit, const Observations& observations,
                       CalibrationOptions& options) {
  try {
    options.priors = parse_priors(prior, observations.priors.value_or(CalibrationPriors{}));
  } catch (const std::invalid_argument& e) {
    throw InputError("prior", "", e.what());
  }
  try {
    options.bounds = parse_bounds(bounds, observations.bounds.value_or(MaterialBounds{}));
  } catch (const std::invalid_argument& e) {
    throw InputError("bounds", "", e.what());
  }
  const std::string outside = outside_bounds(ParameterSpace(scene, fit, camera_count(observations)),
                                             PhysicalParameters::of(scene), options.bounds);
  if (!outside.empty())
    throw InputError("bounds", "", outside + ": the scene's value is outside these bounds");
}

Calibration run_calibrate(const SceneHandle& s, const py::object& observations_in,
                          const py::object& fit_in, Integer max_iterations, Real max_seconds,
                          const std::string& prior, const std::string& bounds) {
  const Scene& scene = *s.scene;
  const FitSelection fit = fit_from(fit_in.is_none() ? py::str(default_fit(scene)) : fit_in);
  CalibrationOptions options{.max_iterations = max_iterations};
  if (max_iterations < 1 || max_iterations > 1000)
    throw InputError("max_iterations", "", "a number from 1 to 1000", max_iterations);
  if (!(max_seconds > 0)) throw InputError("max_seconds", "", "a positive number", max_seconds);
  const Observations observations = observations_from(observations_in, scene);
  priors_and_bounds(prior, bounds, scene, fit, observations, options);

  py::gil_scoped_release release;
  Calibration out;
  try {
    options.max_seconds = max_seconds.value;
    static_cast<CalibrationResult&>(out) = calibrate(scene, observations, fit, options);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {  // a frame's equilibrium not found
    throw SolverError(std::string("calibrate: ") + e.what());
  }
  if (!finite(out)) throw SolverError("calibrate: the result is not finite (" + out.reason + ")");
  out.calibrated = scene_handle(out.scene, s.document);
  return out;
}

}  // namespace

void bind_calibration(py::module_& m) {
  py::class_<FittedParameter>(m, "FittedParameter", "One calibrated parameter (REPORT.json).")
      .def_readonly("name", &FittedParameter::name,
                    "'youngs_modulus', 'poisson_ratio', 'density' or 'grip_offsets.<ee>.x' … "
                    "'.rz'.")
      .def_readonly("unit", &FittedParameter::unit, "'Pa', '', 'kg/m^3', 'm' or 'rad'.")
      .def_readonly("initial", &FittedParameter::initial, "The scene's value.")
      .def_readonly("fitted", &FittedParameter::fitted, "The calibrated value.")
      .def_property_readonly(
          "standard_deviation",
          [](const FittedParameter& p) -> std::optional<double> {
            if (p.held) return std::nullopt;
            return p.standard_deviation;
          },
          "Its standard deviation (from the frames' sigma); None when held.")
      .def_property_readonly(
          "identifiable", [](const FittedParameter& p) { return !p.held; },
          "False: the observations cannot determine it; held at its initial value.")
      .def_property_readonly(
          "verdict", [](const FittedParameter& p) { return std::string(to_string(p.verdict)); },
          "'determined', 'weakly determined' (fitted, its standard deviation large) or 'not "
          "determined' (held), judged at the fitted point.")
      .def_property_readonly(
          "prior",
          [](const FittedParameter& p) -> std::optional<double> {
            if (p.prior > 0) return p.prior;
            return std::nullopt;
          },
          "Its prior's standard deviation in `unit`; None without a prior.")
      .def_readonly("implausible", &FittedParameter::implausible,
                    "Fitted more than 3 prior standard deviations from its initial value.")
      .def_readonly("trades_off_with", &FittedParameter::trades_off_with,
                    "The parameters it trades off with (not or weakly determined).")
      .def_readonly("suggestion", &FittedParameter::suggestion,
                    "What observations would determine it; empty when determined.");

  py::class_<UnidentifiedDirection>(
      m, "UnidentifiedDirection",
      "A combination of parameters the observations cannot determine (REPORT.json's "
      "identifiability).")
      .def_property_readonly(
          "not_determined",
          [](const UnidentifiedDirection& d) {
            return std::map<std::string, double>(d.combination.begin(), d.combination.end());
          },
          "The combination: {parameter coordinate: weight}.")
      .def_readonly("standard_deviation_in_scales", &UnidentifiedDirection::standard_deviation,
                    "Its standard deviation in units of the coordinates' typical scales.")
      .def_readonly("held_at_initial_value", &UnidentifiedDirection::held,
                    "The parameter kept at its initial value for it.")
      .def_readonly("suggestion", &UnidentifiedDirection::suggestion,
                    "What observations would determine it.");

  py::class_<FrameFit>(m, "FrameFit", "The fit of one observed frame.")
      .def_readonly("rms_before", &FrameFit::rms_before, "RMS residual before, m.")
      .def_readonly("rms_after", &FrameFit::rms_after, "RMS residual after, m.")
      .def_readonly("markers", &FrameFit::markers, "Markers observed.")
      .def_readonly("points", &FrameFit::points, "Cloud points observed.")
      .def_readonly("inlier_points_after", &FrameFit::inlier_points_after,
                    "Cloud points counted as inliers at the end.");

  py::class_<Calibration>(m, "CalibrationResult",
                          "What `shapectl calibrate` computes: REPORT.json's fields and the "
                          "calibrated scene.")
      .def_readonly("scene", &Calibration::calibrated,
                    "The scene with the fitted values (its to_dict() is CALIBRATED.json).")
      .def_readonly(
          "converged", &CalibrationResult::converged,
          "Whether the fit converged (the CLI exits 2 when not, with the best values so far).")
      .def_readonly("reason", &CalibrationResult::reason, "Why it stopped.")
      .def_readonly("iterations", &CalibrationResult::iterations, "Levenberg–Marquardt iterations.")
      .def_readonly("seconds", &CalibrationResult::seconds, "Time taken, s.")
      .def_readonly("parameters", &CalibrationResult::parameters,
                    "One FittedParameter per fitted coordinate (held ones included, marked).")
      .def_readonly("identifiability", &CalibrationResult::unidentified,
                    "One UnidentifiedDirection per combination the observations cannot determine.")
      .def_readonly("implausible", &CalibrationResult::implausible,
                    "Names of the parameters fitted more than 3 prior standard deviations away.")
      .def_readonly("rms_before", &CalibrationResult::rms_before,
                    "RMS residual over all frames before, m.")
      .def_readonly("rms_after", &CalibrationResult::rms_after,
                    "RMS residual over all frames after, m.")
      .def_readonly("chi_squared_per_dof", &CalibrationResult::chi_squared_per_dof,
                    "χ²/dof: about 1 when the model fits to the noise level.")
      .def_readonly("frames", &CalibrationResult::frames, "One FrameFit per observed frame.");

  m.def("calibrate", &run_calibrate, py::arg("scene"), py::arg("observations"), py::kw_only(),
        py::arg("fit") = py::none(), py::arg("max_iterations") = 30, py::arg("max_seconds") = 300.0,
        py::arg("prior") = "", py::arg("bounds") = "",
        "Fits the scene's physical parameters to observations of the real object, as `shapectl "
        "calibrate` (docs/calibration.md). observations: an OBSERVATIONS.json path, or a dict "
        "of its schema (numpy arrays allowed; a points_file relative to the current "
        "directory; a frame's loads and object_pose as in the file). fit: a comma-separated "
        "string or a list of youngs_modulus, poisson_ratio, density, grip_offsets, object_pose, "
        "regions[K].youngs_modulus (.poisson_ratio, .density) (default: youngs_modulus and "
        "grip_offsets with a robot, youngs_modulus and object_pose without). max_seconds: the "
        "fit's time budget; spent, it stops with the best values so far (converged False). prior, "
        "bounds: as the CLI's --prior and --bounds (docs/calibration.md), over the observations' "
        "own \"priors\" and \"bounds\". Raises ValueError for bad "
        "input (the CLI's message; a dict is named 'observations'), SolverError when a frame's "
        "equilibrium cannot be found or the budget is spent before a first fit. Releases the GIL "
        "while it runs.");
}

}  // namespace shapectl::python
