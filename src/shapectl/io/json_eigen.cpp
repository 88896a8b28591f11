#include <shapectl/io/json_eigen.hpp>

#include <algorithm>
#include <cmath>

namespace shapectl {

nlohmann::json vec3_json(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json points_json(const std::vector<Vec3>& points) {
  nlohmann::json out = nlohmann::json::array();
  for (const Vec3& p : points) out.push_back(vec3_json(p));
  return out;
}

nlohmann::json positions_json(const Positions& x) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) out.push_back(vec3_json(x.segment<3>(3 * i)));
  return out;
}

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

Eigen::VectorXd vector_from_json(const nlohmann::json& j, std::optional<double> null_value) {
  if (!null_value) {
    const auto v = j.get<std::vector<double>>();
    return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  }
  Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
  for (std::size_t i = 0; i < j.size(); ++i)
    v[static_cast<Eigen::Index>(i)] = j[i].is_null() ? *null_value : j[i].get<double>();
  return v;
}

nlohmann::json scene_pose_json(const Eigen::Isometry3d& T) {
  return {{"position", vec3_json(T.translation())},
          {"rpy", vec3_json(rpy_from_rotation(T.linear()))}};
}

Mat3 rotation_from_rpy(const Vec3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

// Closed form with pitch in [−π/2, π/2]: a small rotation gives small angles (Eigen's
// eulerAngles keeps yaw in [0, π] and may answer a small rotation with angles near ±π).
Vec3 rpy_from_rotation(const Mat3& R) {
  return {std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
          std::atan2(R(1, 0), R(0, 0))};
}

nlohmann::json result_pose_json(const Vec3& position, const Mat3& rotation) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(vec3_json(rotation.row(r).transpose()));
  return {{"position", vec3_json(position)}, {"rotation", rows}};
}

nlohmann::json message_pose_json(const Eigen::Isometry3d& T) {
  nlohmann::json out = nlohmann::json::array();
  const Eigen::Matrix4d& m = T.matrix();
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) out.push_back(m(row, col));
  return out;
}

}  // namespace shapectl
