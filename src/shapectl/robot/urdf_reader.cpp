// RobotModel from URDF text: urdfdom parses, this file checks and flattens the tree.
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/robot/robot_description.hpp>
#include <shapectl/robot/robot_model.hpp>
#include <shapectl/robot/xml_depth.hpp>

namespace shapectl {

namespace {

// urdfdom reports problems through console_bridge; collect them so the InputError can say why.
class CapturedLog : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) lines.push_back(text);
  }
  std::vector<std::string> lines;
};

// Bounds checked before urdfdom sees the text: TinyXML recurses once per nested element
// (max_xml_depth), and urdfdom's links free each other recursively down a chain.
constexpr std::size_t max_urdf_elements = 2000;  // links and joints each; YuMi has 38 links

// The value of attribute `name` in an element's opening tag `head`, or nullopt.
std::optional<std::string> attribute(std::string_view head, std::string_view name) {
  for (std::size_t at = head.find(name); at != std::string_view::npos;
       at = head.find(name, at + 1)) {
    if (at == 0 || !std::isspace(static_cast<unsigned char>(head[at - 1]))) continue;
    std::size_t k = at + name.size();
    while (k < head.size() && std::isspace(static_cast<unsigned char>(head[k]))) ++k;
    if (k >= head.size() || head[k] != '=') continue;
    ++k;
    while (k < head.size() && std::isspace(static_cast<unsigned char>(head[k]))) ++k;
    if (k >= head.size() || (head[k] != '"' && head[k] != '\'')) continue;
    const std::size_t end = head.find_first_of("\"'", k + 1);
    if (end == std::string_view::npos) return std::nullopt;
    return std::string(head.substr(k + 1, end - k - 1));
  }
  return std::nullopt;
}

// First line of each top-level <tag name="..."> element, for messages and sibling order.
// <joint> elements inside <transmission> carry no type attribute, so joints need `type=`.
// Throws when there are more than max_urdf_elements of them.
std::map<std::string, int> element_lines(const std::string& xml, const std::string& tag,
                                         bool need_type, const std::string& source) {
  std::map<std::string, int> lines;
  const std::string open = "<" + tag;
  std::size_t counted_to = 0;  // lines are counted incrementally: one pass over the text
  int line = 1;
  std::size_t elements = 0;
  for (std::size_t at = xml.find(open); at != std::string::npos; at = xml.find(open, at + 1)) {
    const char next = at + open.size() < xml.size() ? xml[at + open.size()] : '>';
    if (!std::isspace(static_cast<unsigned char>(next))) continue;
    // The tag ends at '>'; stopping at the next '<' too keeps the scan linear in bad text.
    const std::size_t end = xml.find_first_of("<>", at + 1);
    const std::string_view head =
        std::string_view(xml).substr(at, end == std::string::npos ? std::string::npos : end - at);
    if (need_type && head.find("type") == std::string::npos) continue;
    if (++elements > max_urdf_elements)
      throw InputError(source, "",
                       "more than " + std::to_string(max_urdf_elements) + " <" + tag +
                           "> elements (the limit for a robot)");
    const auto name = attribute(head, "name");
    if (!name) continue;
    line += static_cast<int>(std::count(xml.begin() + static_cast<long>(counted_to),
                                        xml.begin() + static_cast<long>(at), '\n'));
    counted_to = at;
    lines.emplace(*name, line);  // keeps the first
  }
  return lines;
}

// The encoding a byte order mark announces ("UTF-16 (little-endian)"), or "" for none or UTF-8's.
std::string bom_encoding(std::string_view text) {
  const auto starts = [&](std::string_view bom) { return text.substr(0, bom.size()) == bom; };
  using namespace std::string_view_literals;
  if (starts("\xFF\xFE\0\0"sv)) return "UTF-32 (little-endian)";
  if (starts("\0\0\xFE\xFF"sv)) return "UTF-32 (big-endian)";
  if (starts("\xFF\xFE"sv)) return "UTF-16 (little-endian)";
  if (starts("\xFE\xFF"sv)) return "UTF-16 (big-endian)";
  return "";
}

// The text must be UTF-8 and nest no deeper than max_xml_depth before TinyXML parses it. UTF-16
// or UTF-32 would otherwise be scanned as bytes, its NULs hiding every closing tag.
const std::string& checked_text(const std::string& xml, const std::string& source) {
  if (const std::string encoding = bom_encoding(xml); !encoding.empty())
    throw InputError(source, "", "URDF must be UTF-8 text; found " + encoding);
  if (const std::size_t nul = xml.find('\0'); nul != std::string::npos)
    throw InputError(
        source + ":" +
            std::to_string(1 + std::count(xml.begin(), xml.begin() + static_cast<long>(nul), '\n')),
        "",
        "URDF must be UTF-8 text; found a NUL byte (UTF-16 or UTF-32 without a byte order mark?)");
  if (const std::size_t at = xml_too_deep_at(xml, max_xml_depth); at != std::string_view::npos)
    throw InputError(
        source + ":" +
            std::to_string(1 + std::count(xml.begin(), xml.begin() + static_cast<long>(at), '\n')),
        "", "XML elements nested deeper than " + std::to_string(max_xml_depth) + " levels");
  return xml;
}

// "link 'name'" with the name cut to a readable length.
std::string named(std::string_view kind, std::string_view name) {
  return std::string(kind) + " '" + bounded_preview(name) + "'";
}

}  // namespace

class UrdfReader {
 public:
  UrdfReader(const std::string& xml, const std::string& source)
      : source_(source),
        joint_lines_(element_lines(checked_text(xml, source), "joint", true, source)),
        link_lines_(element_lines(xml, "link", false, source)) {}

  RobotModel read(const std::string& xml) {
    const urdf::ModelInterfaceSharedPtr urdf = parse(xml);
    check_single_parents(*urdf);
    RobotModel model;
    model.name_ = urdf->getName();
    model.source_ = source_;
    add_tree(*urdf, model);
    for (const auto& [name, link] : urdf->links_)
      if (!model.find_link(name))
        throw InputError(where_link(name), named("link", name),
                         "not reachable from the root " + named("link", urdf->getRoot()->name) +
                             " (a kinematic loop?)");
    resolve_mimics(*urdf, model);
    if (ignored_collision_meshes_ > 0)
      model.warnings_.push_back(source_ + ": " + std::to_string(ignored_collision_meshes_) +
                                " collision meshes ignored for the collision model (the "
                                "collision spheres are the collision model), first: " +
                                first_ignored_);
    model.fixed_values_ = Eigen::VectorXd::Zero(model.joint_count());
    std::vector<std::string> movable;
    for (const Joint& joint : model.joints_)
      if (joint.movable() && joint.mimic_master < 0) movable.push_back(joint.name);
    model.set_active_joints(movable);
    return model;
  }

 private:
  urdf::ModelInterfaceSharedPtr parse(const std::string& xml) {
    static std::mutex log_mutex;  // console_bridge's handler is process-wide
    std::lock_guard lock(log_mutex);
    CapturedLog log;
    console_bridge::useOutputHandler(&log);
    urdf::ModelInterfaceSharedPtr urdf;
    std::string thrown;
    try {
      urdf = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      thrown = e.what();
    }
    console_bridge::restorePreviousOutputHandler();
    if (urdf) return urdf;
    std::string why = thrown;
    for (const auto& line : log.lines) why += (why.empty() ? "" : "; ") + line;
    throw InputError(source_, "", "not a valid URDF: " + (why.empty() ? "parse failed" : why));
  }

  // urdfdom silently keeps the last parent when a link is the child of two joints.
  void check_single_parents(const urdf::ModelInterface& urdf) const {
    std::map<std::string, std::string> parent_joint;
    for (const auto& [name, joint] : urdf.joints_) {
      const auto [it, fresh] = parent_joint.emplace(joint->child_link_name, name);
      if (!fresh)
        throw InputError(where_joint(name), named("joint", name),
                         named("link", joint->child_link_name) + " already has parent " +
                             named("joint", it->second) + " (kinematic loop; URDF must be a tree)");
    }
  }

  // Depth first from the root, siblings in file order, with an explicit stack: a URDF chain
  // may be long. Each joint is added just before its child link's subtree.
  void add_tree(const urdf::ModelInterface& urdf, RobotModel& model) {
    add_link(*urdf.getRoot(), -1, model);
    std::vector<std::pair<urdf::JointSharedPtr, int>> pending;  // joint, its parent link
    push_children(*urdf.getRoot(), 0, pending);
    while (!pending.empty()) {
      const auto [joint, parent_link] = pending.back();
      pending.pop_back();
      const int j = model.joint_count();
      model.joints_.push_back(convert_joint(*joint, parent_link));
      model.joint_by_name_[joint->name] = j;
      const urdf::LinkConstSharedPtr child = urdf.getLink(joint->child_link_name);
      const int child_index = add_link(*child, j, model);
      push_children(*child, child_index, pending);
    }
  }

  int add_link(const urdf::Link& link, int parent_joint, RobotModel& model) {
    const int index = model.link_count();
    Link out;
    out.name = link.name;
    out.parent_joint = parent_joint;
    for (const auto& visual : link.visual_array)
      if (visual &&
          add_shape(link.name, "visual", visual->geometry, visual->origin, out.visual_shapes))
        out.visual_shapes.back().rgba = material_color(visual->material);
    for (const auto& collision : link.collision_array)
      if (collision)
        add_shape(link.name, "collision", collision->geometry, collision->origin,
                  out.collision_shapes);
    model.links_.push_back(std::move(out));
    model.link_by_name_[link.name] = index;
    if (parent_joint >= 0) model.joints_[static_cast<std::size_t>(parent_joint)].child_link = index;
    return index;
  }

  // Pushes the link's child joints so that the first in file order is popped first.
  void push_children(const urdf::Link& link, int index,
                     std::vector<std::pair<urdf::JointSharedPtr, int>>& pending) const {
    std::vector<urdf::JointSharedPtr> children = link.child_joints;
    std::sort(children.begin(), children.end(), [&](const auto& a, const auto& b) {
      return std::pair(line_of(joint_lines_, a->name), a->name) <
             std::pair(line_of(joint_lines_, b->name), b->name);
    });
    for (auto it = children.rbegin(); it != children.rend(); ++it) pending.emplace_back(*it, index);
  }

  Joint convert_joint(const urdf::Joint& in, int parent_link) const {
    const std::string where = where_joint(in.name);
    const std::string element = named("joint", in.name);
    Joint out;
    out.name = in.name;
    out.parent_link = parent_link;
    out.T_parent_child = pose(in.parent_to_joint_origin_transform, where, element + ": origin");
    const double inf = std::numeric_limits<double>::infinity();
    switch (in.type) {
      case urdf::Joint::FIXED: out.type = JointType::Fixed; return out;
      case urdf::Joint::REVOLUTE: out.type = JointType::Revolute; break;
      case urdf::Joint::CONTINUOUS: out.type = JointType::Continuous; break;
      case urdf::Joint::PRISMATIC: out.type = JointType::Prismatic; break;
      default:
        throw InputError(
            where, element,
            "unsupported joint type; expected revolute, continuous, prismatic or fixed");
    }
    const Vec3 axis(in.axis.x, in.axis.y, in.axis.z);
    if (!axis.allFinite() || !(axis.norm() > 1e-12))
      throw InputError(where, element + ": axis", "a finite non-zero vector", vec_text(axis));
    out.axis = axis.normalized();
    out.lower = -inf;
    out.upper = inf;
    out.velocity = inf;
    if (in.limits) {
      if (!std::isfinite(in.limits->velocity) || in.limits->velocity < 0)
        throw InputError(where, element + ": limit velocity", "a finite non-negative number",
                         in.limits->velocity);
      if (in.limits->velocity > 0) out.velocity = in.limits->velocity;
      if (out.type != JointType::Continuous) {
        if (!std::isfinite(in.limits->lower) || !std::isfinite(in.limits->upper))
          throw InputError(where, element + ": limit", "finite lower and upper",
                           std::to_string(in.limits->lower) + " / " +
                               std::to_string(in.limits->upper));
        if (in.limits->lower > in.limits->upper)
          throw InputError(where, element,
                           "limit lower " + number_text(in.limits->lower) + " > upper " +
                               number_text(in.limits->upper));
        out.lower = in.limits->lower;
        out.upper = in.limits->upper;
      }
    } else if (out.type != JointType::Continuous) {
      throw InputError(where, element, "a <limit> element (required for revolute and prismatic)");
    }
    return out;
  }

  // Mimic chains end at a joint that mimics nothing; factors compose along the way.
  void resolve_mimics(const urdf::ModelInterface& urdf, RobotModel& model) const {
    for (Joint& joint : model.joints_) {
      const auto in = urdf.getJoint(joint.name);
      if (!in->mimic || !joint.movable()) continue;
      const std::string where = where_joint(joint.name);
      const std::string element = named("joint", joint.name) + ": mimic";
      double multiplier = 1, offset = 0;
      urdf::JointConstSharedPtr current = in;
      std::set<std::string> seen{joint.name};
      while (current->mimic) {
        const std::string& master = current->mimic->joint_name;
        if (!std::isfinite(current->mimic->multiplier) || !std::isfinite(current->mimic->offset))
          throw InputError(where, element, "finite multiplier and offset");
        offset = current->mimic->multiplier * offset + current->mimic->offset;
        multiplier *= current->mimic->multiplier;
        if (!seen.insert(master).second)
          throw InputError(where, element,
                           "mimic joints form a cycle through '" + bounded_preview(master) + "'");
        current = urdf.getJoint(master);
        if (!current) throw InputError(where, element, "unknown " + named("joint", master));
        if (current->type == urdf::Joint::FIXED)
          throw InputError(where, element, named("joint", master) + " is fixed");
      }
      joint.mimic_master = model.joint_index(current->name);
      joint.mimic_multiplier = multiplier;
      joint.mimic_offset = offset;
    }
  }

  // urdfdom resolves a named material to its robot-level definition. A texture-only material
  // keeps urdfdom's default colour, opaque black: that is no colour, not a black robot.
  static std::optional<Eigen::Vector4d> material_color(const urdf::MaterialSharedPtr& material) {
    if (!material) return std::nullopt;
    const urdf::Color& c = material->color;
    const Eigen::Vector4d rgba(c.r, c.g, c.b, c.a);
    const bool default_color = rgba == Eigen::Vector4d(0, 0, 0, 1);
    if (!rgba.allFinite() || (default_color && !material->texture_filename.empty()))
      return std::nullopt;
    return rgba.cwiseMax(0.0).cwiseMin(1.0);
  }

  // Returns whether a shape was added (collision meshes are not).
  bool add_shape(const std::string& link, const std::string& kind,
                 const urdf::GeometrySharedPtr& geometry, const urdf::Pose& origin,
                 std::vector<Shape>& shapes) {
    if (!geometry) return false;
    const std::string where = where_link(link);
    const std::string element = named("link", link) + ": " + kind;
    Shape shape;
    shape.T_link_shape = pose(origin, where, element + " origin");
    auto positive = [&](double v, const std::string& what) {
      if (!std::isfinite(v) || !(v > 0))
        throw InputError(where, element + " " + what, "a positive number", v);
      return v;
    };
    switch (geometry->type) {
      case urdf::Geometry::SPHERE: {
        shape.kind = Shape::Kind::Sphere;
        shape.radius =
            positive(static_cast<const urdf::Sphere&>(*geometry).radius, "sphere radius");
        break;
      }
      case urdf::Geometry::BOX: {
        const auto& dim = static_cast<const urdf::Box&>(*geometry).dim;
        shape.kind = Shape::Kind::Box;
        shape.box_size = {positive(dim.x, "box size x"), positive(dim.y, "box size y"),
                          positive(dim.z, "box size z")};
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(*geometry);
        shape.kind = Shape::Kind::Cylinder;
        shape.radius = positive(cylinder.radius, "cylinder radius");
        shape.length = positive(cylinder.length, "cylinder length");
        break;
      }
      case urdf::Geometry::MESH: {
        const auto& mesh = static_cast<const urdf::Mesh&>(*geometry);
        if (kind != "visual") {
          if (ignored_collision_meshes_++ == 0)
            first_ignored_ = element + " mesh '" + bounded_preview(mesh.filename) + "'";
          return false;
        }
        shape.kind = Shape::Kind::Mesh;
        shape.mesh_filename = mesh.filename;
        shape.mesh_scale = {mesh.scale.x, mesh.scale.y, mesh.scale.z};
        if (!shape.mesh_scale.allFinite() || !(shape.mesh_scale.cwiseAbs().minCoeff() > 0))
          throw InputError(where, element + " mesh scale", "three finite non-zero numbers",
                           vec_text(shape.mesh_scale));
        break;
      }
      default: return false;
    }
    shapes.push_back(shape);
    return true;
  }

  Eigen::Isometry3d pose(const urdf::Pose& p, const std::string& where,
                         const std::string& element) const {
    const Vec3 t(p.position.x, p.position.y, p.position.z);
    const Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
    if (!t.allFinite() || !q.coeffs().allFinite())
      throw InputError(where, element, "finite numbers", vec_text(t));
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() = t;
    return T;
  }

  static int line_of(const std::map<std::string, int>& lines, const std::string& name) {
    const auto it = lines.find(name);
    return it == lines.end() ? std::numeric_limits<int>::max() : it->second;
  }
  std::string where_joint(const std::string& name) const { return located(joint_lines_, name); }
  std::string where_link(const std::string& name) const { return located(link_lines_, name); }
  std::string located(const std::map<std::string, int>& lines, const std::string& name) const {
    const auto it = lines.find(name);
    return it == lines.end() ? source_ : source_ + ":" + std::to_string(it->second);
  }
  static std::string number_text(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  static std::string vec_text(const Vec3& v) {
    return number_text(v.x()) + " " + number_text(v.y()) + " " + number_text(v.z());
  }

  std::string source_;
  std::map<std::string, int> joint_lines_;
  std::map<std::string, int> link_lines_;
  int ignored_collision_meshes_ = 0;
  std::string first_ignored_;
};

RobotModel RobotModel::from_urdf_string(const std::string& xml, const std::string& source_name) {
  return UrdfReader(xml, source_name).read(xml);
}

RobotModel RobotModel::load_urdf_file(const std::filesystem::path& file,
                                      const XacroOptions& xacro) {
  return from_urdf_string(read_robot_description(file, xacro), file.string());
}

}  // namespace shapectl
