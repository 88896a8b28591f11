// The xacro expander: each construct of the supported subset, and each bad input naming
// file:line and what was expected.
#include <shapectl/robot/xacro_expander.hpp>

#include <gtest/gtest.h>

#include <numbers>

#include <shapectl/robot/robot_model.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using test::input_error_of;
using test::TempDir;

std::string robot(const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"r\" "
         "xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n" +
         body + "</robot>\n";
}

// The expansion of `body` written as robot.urdf.xacro.
std::string expand(const std::string& body, const XacroOptions& options = {}) {
  const TempDir dir;
  return expand_xacro_file(dir.write("robot.urdf.xacro", robot(body)), options);
}

// The InputError of expanding `body`, with the temporary folder replaced by "DIR".
std::string error_of(const std::string& body, const XacroOptions& options = {}) {
  const TempDir dir;
  const auto file = dir.write("robot.urdf.xacro", robot(body));
  std::string message = input_error_of([&] { expand_xacro_file(file, options); });
  for (std::size_t at; (at = message.find(dir.path().string())) != std::string::npos;)
    message.replace(at, dir.path().string().size(), "DIR");
  return message;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(XacroExpander, PropertiesAndExpressionsInAttributesAndText) {
  const std::string out = expand(R"(
  <xacro:property name="d1" value="0.089159"/>
  <xacro:property name="twice" value="${2 * d1}"/>
  <xacro:property name="name" value="base"/>
  <link name="${name}_link"><mass>${twice}</mass></link>
  <joint name="j" type="revolute"><origin xyz="0 0 ${d1}" rpy="0 ${pi/2} 0"/></joint>
  <escaped value="$${not_an_expression}"/>
)");
  EXPECT_TRUE(contains(out, "<link name=\"base_link\">")) << out;
  EXPECT_TRUE(contains(out, "<mass>0.178318</mass>")) << out;
  EXPECT_TRUE(contains(out, "xyz=\"0 0 0.089159\" rpy=\"0 1.5707963267948966 0\"")) << out;
  EXPECT_TRUE(contains(out, "value=\"${not_an_expression}\"")) << out;
  EXPECT_FALSE(contains(out, "xacro:")) << out;
}

TEST(XacroExpander, MacrosWithDefaultsBlocksAndNesting) {
  const std::string out = expand(R"(
  <xacro:property name="side" value="left"/>
  <xacro:macro name="inertial" params="mass *origin">
    <inertial><mass value="${mass}"/><xacro:insert_block name="origin"/></inertial>
  </xacro:macro>
  <xacro:macro name="arm_link" params="name mass:=1.5 side:=^ **extras">
    <link name="${side}_${name}">
      <xacro:inertial mass="${mass * 2}"><origin xyz="0 0 ${mass}"/></xacro:inertial>
      <xacro:insert_block name="extras"/>
    </link>
  </xacro:macro>
  <xacro:arm_link name="upper"><extras><visual/><collision/></extras></xacro:arm_link>
  <xacro:arm_link name="lower" mass="0.5" side="right"><extras/></xacro:arm_link>
)");
  EXPECT_TRUE(contains(out, "<link name=\"left_upper\">")) << out;  // side:=^ from the caller
  EXPECT_TRUE(contains(out, "<mass value=\"3.0\" />")) << out;
  EXPECT_TRUE(contains(out, "<origin xyz=\"0 0 1.5\" />")) << out;
  EXPECT_TRUE(contains(out, "<visual />")) << out;  // **extras: the block's children
  EXPECT_FALSE(contains(out, "<extras")) << out;
  EXPECT_TRUE(contains(out, "<link name=\"right_lower\">")) << out;
  EXPECT_TRUE(contains(out, "<mass value=\"1.0\" />")) << out;
}

TEST(XacroExpander, PropertiesDefinedInAMacroStayInIt) {
  const std::string body = R"(
  <xacro:macro name="m" params="">
    <xacro:property name="local" value="1"/>
    <xacro:property name="exported" value="2" scope="parent"/>
  </xacro:macro>
  <xacro:m/>
  <a value="${exported}"/>
)";
  EXPECT_TRUE(contains(expand(body), "<a value=\"2\" />"));
  EXPECT_EQ(error_of(body + "  <b value=\"${local}\"/>\n"),
            "DIR/robot.urdf.xacro:10: bad expression ${local}: undefined property 'local'");
}

TEST(XacroExpander, ConditionsAcceptBooleansNumbersAndExpressions) {
  const std::string out = expand(R"(
  <xacro:property name="limited" value="false"/>
  <xacro:if value="true"><a/></xacro:if>
  <xacro:if value="0"><b/></xacro:if>
  <xacro:unless value="${limited}"><c/></xacro:unless>
  <xacro:if value="${1 &lt; 2 and not limited}"><d/></xacro:if>
  <xacro:unless value="1"><e/></xacro:unless>
)");
  EXPECT_TRUE(contains(out, "<a />"));
  EXPECT_FALSE(contains(out, "<b />"));
  EXPECT_TRUE(contains(out, "<c />"));
  EXPECT_TRUE(contains(out, "<d />"));
  EXPECT_FALSE(contains(out, "<e />"));
}

TEST(XacroExpander, ArgsTakeDefaultsOrTheGivenValue) {
  const std::string body = R"(
  <xacro:arg name="prefix" default="left_"/>
  <link name="$(arg prefix)base"/>
)";
  EXPECT_TRUE(contains(expand(body), "<link name=\"left_base\" />"));
  XacroOptions options;
  options.args["prefix"] = "right_";
  EXPECT_TRUE(contains(expand(body, options), "<link name=\"right_base\" />"));
}

TEST(XacroExpander, IncludesRelativeFilesAndPackagesWithTheirMacros) {
  const TempDir dir;
  dir.write("my_pkg/package.xml", "<package><name>my_pkg</name></package>");
  dir.write("my_pkg/urdf/parts.xacro", robot(R"(
  <xacro:include filename="more/limits.xacro"/>
  <xacro:macro name="part" params="n"><link name="part_${n}"/><limit value="${max_speed}"/></xacro:macro>
)"));
  dir.write("my_pkg/urdf/more/limits.xacro",
            robot("<xacro:property name=\"max_speed\" value=\"2.5\"/>\n"));
  const TempDir elsewhere;  // not above my_pkg, whose parent folder $(find) also searches
  const auto top = elsewhere.write("top.urdf.xacro", robot(R"(
  <xacro:include filename="$(find my_pkg)/urdf/parts.xacro"/>
  <xacro:part n="7"/>
)"));
  XacroOptions options;
  options.package_paths = {dir.path()};
  const std::string out = expand_xacro_file(top, options);
  EXPECT_TRUE(contains(out, "<link name=\"part_7\" />")) << out;
  EXPECT_TRUE(contains(out, "<limit value=\"2.5\" />")) << out;
  // Without the package path the folders above the file are searched: my_pkg is not there.
  EXPECT_TRUE(contains(input_error_of([&] { expand_xacro_file(top); }),
                       "top.urdf.xacro:4: package 'my_pkg' of $(find my_pkg) not found"));
  // In the package, or beside it, the folders above the file find it by name.
  const auto inner = dir.write("my_pkg/urdf/inner.urdf.xacro",
                               robot("<xacro:include filename=\"$(find my_pkg)/urdf/parts.xacro\"/>"
                                     "<xacro:part n=\"1\"/>"));
  EXPECT_TRUE(contains(expand_xacro_file(inner), "part_1"));
}

TEST(XacroExpander, AnExpansionLoadsAsARobotModel) {
  const std::string out = expand(R"(
  <xacro:macro name="segment" params="parent child z">
    <link name="${child}"/>
    <joint name="${parent}_to_${child}" type="revolute">
      <parent link="${parent}"/><child link="${child}"/>
      <origin xyz="0 0 ${z}"/><axis xyz="0 1 0"/>
      <limit lower="${-pi/2}" upper="${pi/2}" effort="1" velocity="1"/>
    </joint>
  </xacro:macro>
  <link name="base"/>
  <xacro:segment parent="base" child="a" z="0.3"/>
  <xacro:segment parent="a" child="b" z="${0.1 + 0.15}"/>
)");
  const RobotModel model = RobotModel::from_urdf_string(out, "expanded");
  ASSERT_EQ(model.joint_count(), 2);
  EXPECT_EQ(model.joints()[1].name, "a_to_b");
  EXPECT_DOUBLE_EQ(model.joints()[1].T_parent_child.translation().z(), 0.25);
  EXPECT_DOUBLE_EQ(model.joints()[0].upper, std::numbers::pi / 2);
}

// ---- bad input: each names file:line and what was expected ----

TEST(XacroExpanderErrors, UndefinedPropertyMacroArgAndBlock) {
  EXPECT_EQ(error_of("\n  <link name=\"${missing}\"/>\n"),
            "DIR/robot.urdf.xacro:4: bad expression ${missing}: undefined property 'missing'");
  EXPECT_TRUE(contains(error_of("\n  <xacro:arm/>\n"),
                       "DIR/robot.urdf.xacro:4: undefined macro 'xacro:arm' (expected a "
                       "xacro:macro of that name, defined before this call"));
  EXPECT_EQ(error_of("  <link name=\"$(arg side)\"/>\n"),
            "DIR/robot.urdf.xacro:3: undefined arg 'side' (declare it with <xacro:arg "
            "name=\"side\" default=\"...\"/> or give --xacro-arg side:=VALUE)");
  EXPECT_TRUE(contains(error_of("  <xacro:insert_block name=\"origin\"/>\n"),
                       "robot.urdf.xacro:3: undefined block 'origin'"));
}

TEST(XacroExpanderErrors, MacroParameters) {
  const std::string macro = "  <xacro:macro name=\"m\" params=\"a *block\"><x/></xacro:macro>\n";
  EXPECT_EQ(error_of(macro + "  <xacro:m><b/></xacro:m>\n"),
            "DIR/robot.urdf.xacro:4: macro 'm' needs parameter 'a' (it has no default)");
  EXPECT_EQ(error_of(macro + "  <xacro:m a=\"1\" c=\"2\"><b/></xacro:m>\n"),
            "DIR/robot.urdf.xacro:4: macro 'm' has no parameter 'c'");
  EXPECT_EQ(error_of(macro + "  <xacro:m a=\"1\"/>\n"),
            "DIR/robot.urdf.xacro:4: macro 'm' expects a block (an element inside the call) "
            "for *block");
}

TEST(XacroExpanderErrors, BadExpressionsAndConditions) {
  EXPECT_EQ(error_of("\n\n  <a v=\"${1 +}\"/>\n"),
            "DIR/robot.urdf.xacro:5: bad expression ${1 +}: expression ends early");
  EXPECT_EQ(error_of("  <a v=\"${1 + 2\"/>\n"),
            "DIR/robot.urdf.xacro:3: '${' without its closing '}' in \"${1 + 2\"");
  EXPECT_EQ(error_of("  <xacro:if value=\"maybe\"><a/></xacro:if>\n"),
            "DIR/robot.urdf.xacro:3: xacro:if value \"maybe\" is \"maybe\": expected true, "
            "false, 1 or 0");
  EXPECT_EQ(error_of("  <a v=\"$(eval 1 + 2)\"/>\n"),
            "DIR/robot.urdf.xacro:3: unsupported substitution $(eval ...) (supported: find, "
            "arg, env, optenv, dirname)");
}

TEST(XacroExpanderErrors, UnsupportedXacroTagsPointToTheConversionRoute) {
  EXPECT_TRUE(contains(error_of("  <xacro:call macro=\"m\"/>\n"),
                       "DIR/robot.urdf.xacro:3: xacro:call is not supported by shapectl's xacro "
                       "expander (docs/robot.md: expand it with ROS's xacro"));
  EXPECT_TRUE(contains(error_of("  <xacro:element xacro:name=\"link\"/>\n"),
                       "xacro:element is not supported"));
}

TEST(XacroExpanderErrors, TheOldSyntaxWithoutThePrefixIsRefused) {
  EXPECT_EQ(error_of("  <include filename=\"parts.xacro\"/>\n"),
            "DIR/robot.urdf.xacro:3: <include> without the xacro: prefix (xacro's old syntax) is "
            "not supported: write <xacro:include>");
  EXPECT_TRUE(contains(expand("  <gazebo><property>kept</property></gazebo>\n"),
                       "<property>kept</property>"));  // not a robot's child: plain XML
}

TEST(XacroExpanderErrors, MissingIncludeAndIncludeCycle) {
  EXPECT_EQ(error_of("\n  <xacro:include filename=\"nowhere.xacro\"/>\n"),
            "DIR/robot.urdf.xacro:4: included file 'DIR/nowhere.xacro' not found");
  const TempDir dir;
  dir.write("a.xacro", robot("  <xacro:include filename=\"b.xacro\"/>\n"));
  dir.write("b.xacro", robot("\n  <xacro:include filename=\"a.xacro\"/>\n"));
  const std::string message = input_error_of([&] { expand_xacro_file(dir.path() / "a.xacro"); });
  EXPECT_TRUE(contains(message, "b.xacro:4: include cycle: '")) << message;
}

TEST(XacroExpanderErrors, IncludeDepthAndMacroRecursionAreBounded) {
  const TempDir dir;
  auto name = [](int i) { return std::string("f").append(std::to_string(i)).append(".xacro"); };
  for (int i = 0; i < 20; ++i)
    dir.write(name(i), robot("  <xacro:include filename=\"" + name(i + 1) + "\"/>\n"));
  dir.write(name(20), robot(""));
  EXPECT_TRUE(contains(input_error_of([&] { expand_xacro_file(dir.path() / "f0.xacro"); }),
                       "f16.xacro:3: includes nested deeper than 16"));
  EXPECT_EQ(error_of(
                "  <xacro:macro name=\"m\" params=\"\"><xacro:m/></xacro:macro>\n  <xacro:m/>\n"),
            "DIR/robot.urdf.xacro:3: macros nested deeper than 64 (a macro calling itself?)");
}

TEST(XacroExpanderErrors, AnExpansionPastTheUrdfSizeLimitStops) {
  // Each level doubles the output: 2^30 links long before the limit is reached.
  std::string body = "  <xacro:macro name=\"m0\" params=\"\"><link name=\"" + std::string(60, 'x') +
                     "\"/></xacro:macro>\n";
  for (int i = 1; i <= 30; ++i)
    body += "  <xacro:macro name=\"m" + std::to_string(i) + "\" params=\"\"><xacro:m" +
            std::to_string(i - 1) + "/><xacro:m" + std::to_string(i - 1) + "/></xacro:macro>\n";
  body += "  <xacro:m30/>\n";
  EXPECT_TRUE(contains(error_of(body), "byte limit for URDF files"));
}

TEST(XacroExpanderErrors, MalformedXml) {
  EXPECT_TRUE(contains(error_of("  <link name=\"a\">\n"), "DIR/robot.urdf.xacro:"));
  EXPECT_TRUE(contains(error_of("  <link name=\"a\">\n"), "not well-formed XML"));
}

}  // namespace
}  // namespace shapectl
