#include <shapectl/calib/parameter_priors.hpp>

#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace shapectl {

namespace {

using Kind = ParameterCoordinate::Kind;

std::vector<std::string> split(const std::string& text, char by) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, by)) out.push_back(item);
  if (!text.empty() && text.back() == by) out.emplace_back();
  return out;
}

bool is_off(const std::string& s) { return s == "none" || s == "off"; }

// A finite number followed by exactly `suffix`; false if it is not one.
bool number_with(const std::string& text, const std::string& suffix, double* value) {
  if (text.size() <= suffix.size() ||
      text.compare(text.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const std::string number = text.substr(0, text.size() - suffix.size());
  char* end = nullptr;
  *value = std::strtod(number.c_str(), &end);
  return end == number.c_str() + number.size() && std::isfinite(*value) && *value > 0;
}

// What one prior's value may be: a length, an angle or a fraction; "none"/"off" is 0.
enum class Quantity { Length, Angle, Fraction };

double prior_value(const std::string& entry, const std::string& text, Quantity q) {
  if (is_off(text)) return 0;
  double v = 0;
  switch (q) {
    case Quantity::Length:
      if (number_with(text, "mm", &v)) return v * 1e-3;
      if (number_with(text, "m", &v)) return v;
      break;
    case Quantity::Angle:
      if (number_with(text, "deg", &v)) return v * M_PI / 180;
      if (number_with(text, "rad", &v)) return v;
      break;
    case Quantity::Fraction:
      if (number_with(text, "%", &v)) return v / 100;
      break;
  }
  static const char* expected[] = {"a positive length in mm or m (10mm), or none",
                                   "a positive angle in deg or rad (2deg), or none",
                                   "a positive percentage (50%), or none"};
  throw std::invalid_argument(entry + ": expected " + expected[static_cast<int>(q)] + ", got \"" +
                              text + "\"");
}

// "5mm/3deg" (or "off") for both halves of a rigid motion's prior.
void motion_prior(const std::string& entry, const std::string& text, double* translation,
                  double* rotation) {
  if (is_off(text)) {
    *translation = *rotation = 0;
    return;
  }
  const std::vector<std::string> parts = split(text, '/');
  if (parts.size() != 2)
    throw std::invalid_argument(entry +
                                ": expected a translation and a rotation as 5mm/3deg, or "
                                "none, got \"" +
                                text + "\"");
  *translation = prior_value(entry, parts[0], Quantity::Length);
  *rotation = prior_value(entry, parts[1], Quantity::Angle);
}

double bound_value(const std::string& entry, const std::string& text, double unbounded) {
  if (text.empty()) return unbounded;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(v))
    throw std::invalid_argument(entry +
                                ": expected LOWER:UPPER (numbers; a side may be empty), "
                                "got \"" +
                                text + "\"");
  return v;
}

double logit_of_poisson(double nu) { return std::log(2 * nu / (1 - 2 * nu)); }

}  // namespace

CalibrationPriors parse_priors(const std::string& text, CalibrationPriors base) {
  if (is_off(text)) return CalibrationPriors::none();
  CalibrationPriors p = base;
  for (const std::string& entry : split(text, ',')) {
    const std::size_t eq = entry.find('=');
    const std::string key = entry.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : entry.substr(eq + 1);
    if (eq == std::string::npos || value.empty())
      throw std::invalid_argument("\"" + entry + "\": expected NAME=VALUE");
    if (key == "object_pose") motion_prior(entry, value, &p.pose_translation, &p.pose_rotation);
    else if (key == "object_pose.translation")
      p.pose_translation = prior_value(entry, value, Quantity::Length);
    else if (key == "object_pose.rotation")
      p.pose_rotation = prior_value(entry, value, Quantity::Angle);
    else if (key == "grip_offsets")
      motion_prior(entry, value, &p.grip_translation, &p.grip_rotation);
    else if (key == "grip_offsets.translation")
      p.grip_translation = prior_value(entry, value, Quantity::Length);
    else if (key == "grip_offsets.rotation")
      p.grip_rotation = prior_value(entry, value, Quantity::Angle);
    else if (key == "camera_poses")
      motion_prior(entry, value, &p.camera_translation, &p.camera_rotation);
    else if (key == "camera_poses.translation")
      p.camera_translation = prior_value(entry, value, Quantity::Length);
    else if (key == "camera_poses.rotation")
      p.camera_rotation = prior_value(entry, value, Quantity::Angle);
    else if (key == "youngs_modulus")
      p.youngs_modulus = prior_value(entry, value, Quantity::Fraction);
    else if (key == "density") p.density = prior_value(entry, value, Quantity::Fraction);
    else if (key == "poisson_ratio")
      p.poisson_ratio = prior_value(entry, value, Quantity::Fraction);
    else
      throw std::invalid_argument(
          "\"" + entry +
          "\": unknown name (expected object_pose, object_pose.translation, object_pose.rotation, "
          "grip_offsets, grip_offsets.translation, grip_offsets.rotation, camera_poses, "
          "camera_poses.translation, camera_poses.rotation, youngs_modulus, "
          "density, poisson_ratio, or off alone)");
  }
  return p;
}

MaterialBounds parse_bounds(const std::string& text, MaterialBounds base) {
  MaterialBounds b = base;
  for (const std::string& entry : split(text, ',')) {
    const std::size_t eq = entry.find('=');
    const std::string key = entry.substr(0, eq);
    const std::vector<std::string> sides =
        eq == std::string::npos ? std::vector<std::string>() : split(entry.substr(eq + 1), ':');
    if (sides.size() != 2)
      throw std::invalid_argument("\"" + entry + "\": expected NAME=LOWER:UPPER");
    ValueInterval* interval = nullptr;
    ValueInterval allowed;
    if (key == "youngs_modulus") interval = &b.youngs_modulus, allowed = {0, INFINITY};
    else if (key == "density") interval = &b.density, allowed = {0, INFINITY};
    else if (key == "poisson_ratio") interval = &b.poisson_ratio, allowed = {0, 0.5};
    else
      throw std::invalid_argument("\"" + entry +
                                  "\": unknown name (expected youngs_modulus, density or "
                                  "poisson_ratio)");
    interval->lower = bound_value(entry, sides[0], allowed.lower);
    interval->upper = bound_value(entry, sides[1], allowed.upper);
    if (!(interval->lower >= allowed.lower && interval->upper <= allowed.upper &&
          interval->lower < interval->upper)) {
      std::ostringstream what;
      what << entry << ": expected " << allowed.lower << " <= LOWER < UPPER <= " << allowed.upper;
      throw std::invalid_argument(what.str());
    }
  }
  return b;
}

double prior_sigma(const CalibrationPriors& priors, const ParameterCoordinate& c,
                   const PhysicalParameters& p) {
  switch (c.kind) {
    case Kind::LogYoungsModulus: return priors.youngs_modulus;
    case Kind::LogDensity: return priors.density;
    // d ln ν / ds = 1 − 2ν: a relative σ of ν is σ / (1 − 2ν) in s.
    case Kind::PoissonLogit:
      return priors.poisson_ratio / (1 - 2 * p.material(c.region).poisson_ratio);
    case Kind::GripTranslation: return priors.grip_translation;
    case Kind::GripRotation: return priors.grip_rotation;
    case Kind::PoseTranslation: return priors.pose_translation;
    case Kind::PoseRotation: return priors.pose_rotation;
    case Kind::CameraTranslation: return priors.camera_translation;
    case Kind::CameraRotation: return priors.camera_rotation;
  }
  return 0;
}

ValueInterval coordinate_bounds(const MaterialBounds& bounds, const ParameterCoordinate& c) {
  const auto log_of = [](const ValueInterval& v) {
    return ValueInterval{v.lower > 0 ? std::log(v.lower) : -INFINITY, std::log(v.upper)};
  };
  switch (c.kind) {
    case Kind::LogYoungsModulus: return log_of(bounds.youngs_modulus);
    case Kind::LogDensity: return log_of(bounds.density);
    case Kind::PoissonLogit:
      return {bounds.poisson_ratio.lower > 0 ? logit_of_poisson(bounds.poisson_ratio.lower)
                                             : -INFINITY,
              bounds.poisson_ratio.upper < 0.5 ? logit_of_poisson(bounds.poisson_ratio.upper)
                                               : INFINITY};
    default: return {};
  }
}

std::string outside_bounds(const ParameterSpace& space, const PhysicalParameters& p,
                           const MaterialBounds& bounds) {
  for (const ParameterCoordinate& c : space.coordinates())
    if (!coordinate_bounds(bounds, c).contains(material_coordinate(c, p))) return c.name;
  return "";
}

double material_coordinate(const ParameterCoordinate& c, const PhysicalParameters& p) {
  const MaterialValues m = p.material(c.region);
  switch (c.kind) {
    case Kind::LogYoungsModulus: return std::log(m.youngs_modulus);
    case Kind::LogDensity: return std::log(m.density);
    case Kind::PoissonLogit: return logit_of_poisson(m.poisson_ratio);
    default: return 0;
  }
}

}  // namespace shapectl
