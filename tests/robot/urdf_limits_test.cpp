// URDF input that used to crash the process: no regex over names, bounded XML nesting and
// element counts, an iterative tree walk, and files that are not regular refused.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <functional>
#include <string>

#include <shapectl/io/input_error.hpp>
#include <shapectl/robot/kinematics.hpp>
#include <shapectl/robot/robot_model.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

std::string error_of(const std::function<void()>& f) { return test::input_error_of(f); }

// A chain of `links` links joined by revolute joints about z, each 0.1 m along x.
std::string chain_urdf(int links) {
  std::string xml = "<robot name=\"chain\">\n<link name=\"l0\"/>\n";
  for (int i = 1; i < links; ++i) {
    const std::string n = std::to_string(i), p = std::to_string(i - 1);
    xml += "<joint name=\"j" + n + "\" type=\"revolute\"><parent link=\"l" + p +
           "\"/><child link=\"l" + n +
           "\"/><origin xyz=\"0.1 0 0\"/><axis xyz=\"0 0 1\"/>"
           "<limit lower=\"-1\" upper=\"1\" velocity=\"1\" effort=\"1\"/></joint>\n<link name=\"l" +
           n + "\"/>\n";
  }
  return xml + "</robot>\n";
}

TEST(UrdfLimits, LongLinkNameIsReadAndEchoedBounded) {
  const std::string name(30'000, 'n');
  const RobotModel model =
      RobotModel::from_urdf_string("<robot name=\"r\"><link name=\"" + name + "\"/></robot>",
                                   "r.urdf");
  EXPECT_EQ(model.links()[0].name, name);
  // A joint to an unknown link: urdfdom refuses, the message stays short.
  const std::string bad = "<robot name=\"r\"><link name=\"a\"/><joint name=\"" + name +
                          "\" type=\"fixed\"><parent link=\"a\"/><child link=\"" + name +
                          "\"/></joint></robot>";
  const std::string message = error_of([&] { RobotModel::from_urdf_string(bad, "r.urdf"); });
  EXPECT_EQ(message.rfind("r.urdf", 0), 0u);
  const std::string unknown = error_of([&] { model.link_index(std::string(50'000, 'x')); });
  EXPECT_EQ(unknown, "r.urdf: link '" + std::string(80, 'x') + "…': unknown link");
}

TEST(UrdfLimits, LongChainIsWalkedWithoutRecursion) {
  const RobotModel model = RobotModel::from_urdf_string(chain_urdf(1500), "chain.urdf");
  ASSERT_EQ(model.link_count(), 1500);
  ASSERT_EQ(model.active_count(), 1499);
  // Every joint at 0: the last link sits 149.9 m along x; tree order is the chain's order.
  const KinematicsState state = forward_kinematics(model, Eigen::VectorXd::Zero(1499));
  EXPECT_NEAR(state.T_world_link.back().translation().x(), 149.9, 1e-9);
  EXPECT_EQ(model.joints()[1498].name, "j1499");
}

TEST(UrdfLimits, ChainOfFourteenThousandLinksIsRefused) {
  EXPECT_EQ(error_of([] { RobotModel::from_urdf_string(chain_urdf(14'000), "chain.urdf"); }),
            "chain.urdf: more than 2000 <joint> elements (the limit for a robot)");
}

TEST(UrdfLimits, DeeplyNestedXmlIsRefusedBeforeParsing) {
  std::string xml = "<?xml version=\"1.0\"?>\n<!-- <a><a><a> -->\n<robot name=\"r\">\n";
  for (int i = 0; i < 40'000; ++i) xml += "<a>";
  for (int i = 0; i < 40'000; ++i) xml += "</a>";
  xml += "</robot>";
  EXPECT_EQ(error_of([&] { RobotModel::from_urdf_string(xml, "deep.urdf"); }),
            "deep.urdf:4: XML elements nested deeper than 100 levels");
  // Self-closing elements, comments and '>' inside attribute values do not nest.
  std::string flat = "<robot name=\"r\"><link name=\"a\"/>";
  for (int i = 0; i < 500; ++i)
    flat += "<!-- <x> --><material name=\"m>" + std::to_string(i) + "\"/>";
  EXPECT_NO_THROW(RobotModel::from_urdf_string(flat + "</robot>", "flat.urdf"));
}

TEST(UrdfLimits, UnclosedTagsAreScannedInOnePass) {
  // Two million "<joint " openings without '>' or "type": a scan to the end from each would
  // take hours; urdfdom then refuses the text.
  std::string xml = "<robot name=\"r\">";
  for (int i = 0; i < 2'000'000; ++i) xml += "<joint ";
  EXPECT_NE(error_of([&] { RobotModel::from_urdf_string(xml, "open.urdf"); }), "");
}

TEST(UrdfLimits, FifoAndOversizeFilesAreRefused) {
  const test::TempDir dir;
  const auto fifo = dir.path() / "robot.urdf";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { RobotModel::load_urdf_file(fifo); }),
            fifo.string() + ": not a regular file (a FIFO)");
  const auto big = dir.write("big.urdf", "<robot name=\"r\"><link name=\"a\"/></robot>" +
                                             std::string(16u << 20, ' '));
  EXPECT_NE(error_of([&] { RobotModel::load_urdf_file(big); }).find("byte limit for URDF files"),
            std::string::npos);
}

// `text` (ASCII) in UTF-16 or UTF-32, little- or big-endian, after `bom`.
std::string widened(const std::string& text, int width, bool little_endian,
                    const std::string& bom) {
  std::string out = bom;
  for (const char c : text) {
    std::string unit(static_cast<std::size_t>(width), '\0');
    unit[little_endian ? 0 : unit.size() - 1] = c;
    out += unit;
  }
  return out;
}

TEST(UrdfLimits, Utf16AndUtf32AreRefusedNamingTheEncodingAndTheFile) {
  const test::TempDir dir;
  const std::string urdf =
      "<?xml version=\"1.0\"?>\n<robot name=\"r\"><link name=\"a\"/></robot>\n";
  ASSERT_NO_THROW(RobotModel::load_urdf_file(dir.write("plain.urdf", urdf)));
  struct Case {
    std::string file, bytes, found;
  };
  const std::vector<Case> cases{
      {"utf16le.urdf", widened(urdf, 2, true, "\xFF\xFE"), "UTF-16 (little-endian)"},
      {"utf16be.urdf", widened(urdf, 2, false, "\xFE\xFF"), "UTF-16 (big-endian)"},
      {"utf32le.urdf", widened(urdf, 4, true, std::string("\xFF\xFE\0\0", 4)),
       "UTF-32 (little-endian)"},
      {"utf32be.urdf", widened(urdf, 4, false, std::string("\0\0\xFE\xFF", 4)),
       "UTF-32 (big-endian)"},
  };
  for (const auto& c : cases) {
    const auto file = dir.write(c.file, c.bytes);
    EXPECT_EQ(error_of([&] { RobotModel::load_urdf_file(file); }),
              file.string() + ": URDF must be UTF-8 text; found " + c.found);
  }
  // Without a byte order mark: the first NUL byte, with its line.
  const auto bare = dir.write("bare.urdf", widened(urdf, 2, true, ""));
  EXPECT_EQ(error_of([&] { RobotModel::load_urdf_file(bare); }),
            bare.string() +
                ":1: URDF must be UTF-8 text; found a NUL byte (UTF-16 or UTF-32 without a byte "
                "order mark?)");
  const std::string nul_in_line_2 =
      "<robot name=\"r\">\n<link name=\"a" + std::string(1, '\0') + "\"/></robot>";
  EXPECT_EQ(error_of([&] {
              RobotModel::from_urdf_string(nul_in_line_2, "nul.urdf");
            }).rfind("nul.urdf:2: URDF must be UTF-8 text; found a NUL byte", 0),
            0u);
  // UTF-8's own byte order mark is UTF-8.
  EXPECT_NO_THROW(RobotModel::from_urdf_string("\xEF\xBB\xBF" + urdf, "bom.urdf"));
}

}  // namespace
}  // namespace shapectl
