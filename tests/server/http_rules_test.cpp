#include <shapectl/server/http_rules.hpp>

#include <gtest/gtest.h>

#include "support/test_support.hpp"

namespace shapectl::server {
namespace {

TEST(HttpRules, ResolvesFilesInsideTheWebRootOnly) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "web/js");
  test::TempDir outside;
  const auto secret = outside.write("secret.txt", "no");
  const auto index = dir.path() / "web/index.html";
  dir.write("web/index.html", "<html>");
  dir.write("web/js/app.js", "x");
  dir.write("web/.hidden", "x");
  std::filesystem::create_symlink(secret, dir.path() / "web/link.txt");
  const auto root = dir.path() / "web";

  EXPECT_EQ(resolve_static_file(root, "/"), std::filesystem::canonical(index));
  EXPECT_EQ(resolve_static_file(root, "/js/app.js?v=1"),
            std::filesystem::canonical(root / "js/app.js"));
  for (const char* bad :
       {"/../web/index.html", "/js/../index.html", "/.hidden", "/js//app.js", "/js/app.js%00",
        "/js\\app.js", "/link.txt", "/missing.js", "/js", "index.html", ""})
    EXPECT_FALSE(resolve_static_file(root, bad)) << bad;
}

TEST(HttpRules, ContentTypesForTheAssetsThePageUses) {
  EXPECT_EQ(content_type("a/index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(content_type("three.module.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(content_type("x.css"), "text/css; charset=utf-8");
  EXPECT_EQ(content_type("gui.png"), "image/png");
  EXPECT_EQ(content_type("blob"), "application/octet-stream");
  EXPECT_EQ(content_type("/pkg/meshes/arm.STL"), "model/stl");
  EXPECT_EQ(content_type("hand.obj"), "model/obj");
  EXPECT_EQ(content_type("hand.dae"), "model/vnd.collada+xml");
}

TEST(HttpRules, RobotMeshRequestsAreANumberAndAKnownExtensionOnly) {
  const auto mesh = parse_robot_mesh_target("/robot-mesh/12.stl?v=2");
  ASSERT_TRUE(mesh);
  EXPECT_EQ(mesh->index, 12u);
  EXPECT_EQ(mesh->extension, "stl");
  EXPECT_EQ(parse_robot_mesh_target("/robot-mesh/0.dae")->index, 0u);
  for (const char* bad : {"/robot-mesh/", "/robot-mesh/7", "/robot-mesh/7.", "/robot-mesh/7.png",
                          "/robot-mesh/07.stl", "/robot-mesh/-1.stl", "/robot-mesh/1e3.stl",
                          "/robot-mesh/../secret.stl", "/robot-mesh/%2e%2e/a.stl",
                          "/robot-mesh//etc/a.stl", "/robot-mesh/1.stl/../../a",
                          "/robot-mesh/9999999.stl", "/js/robot-mesh/1.stl", "/robot-mesh/1.STL"})
    EXPECT_FALSE(parse_robot_mesh_target(bad)) << bad;
}

TEST(HttpRules, HostMustBeLoopbackAnAddressOrTheBoundName) {
  EXPECT_TRUE(host_allowed("127.0.0.1:8080", "127.0.0.1"));
  EXPECT_TRUE(host_allowed("localhost:8080", "127.0.0.1"));
  EXPECT_TRUE(host_allowed("[::1]:8080", "127.0.0.1"));
  EXPECT_TRUE(host_allowed("192.168.1.20:8080", "0.0.0.0"));
  EXPECT_TRUE(host_allowed("robot-pc:8080", "robot-pc"));
  EXPECT_FALSE(host_allowed("evil.example:8080", "127.0.0.1"));
  EXPECT_FALSE(host_allowed("", "127.0.0.1"));
  EXPECT_FALSE(host_allowed("[::1", "127.0.0.1"));
}

TEST(HttpRules, HostMustBeAWellFormedNameQuadOrBracketedIpv6WithAPortInRange) {
  for (const char* good : {"127.0.0.1", "0.0.0.0:1", "255.255.255.255:65535", "[::1]",
                           "[fe80::1]:8080", "[::ffff:127.0.0.1]:80", "LOCALHOST:8080"})
    EXPECT_TRUE(host_allowed(good, "127.0.0.1")) << good;
  for (const char* bad : {"[evil.com]",
                          "[evil.com]:8080",
                          "999.999.999.999",
                          "999.999.999.999:8080",
                          "256.0.0.1",
                          "1.2.3",
                          "1.2.3.4.5",
                          "01.2.3.4",
                          "127.0.0.1:",
                          "127.0.0.1:0",
                          "127.0.0.1:65536",
                          "127.0.0.1:80x",
                          "[::1]x",
                          "[::1]:",
                          "[]",
                          "localhost.",
                          "local_host",
                          "-robot:80",
                          "robot-pc:99999",
                          "a..b"})
    EXPECT_FALSE(host_allowed(bad, "robot-pc")) << bad;
  EXPECT_TRUE(host_allowed("robot-pc:8080", "robot-pc"));
}

TEST(HttpRules, OriginMustBeThePagesOwn) {
  EXPECT_TRUE(origin_allowed("", "127.0.0.1:8080"));
  EXPECT_TRUE(origin_allowed("http://127.0.0.1:8080", "127.0.0.1:8080"));
  EXPECT_FALSE(origin_allowed("http://evil.example", "127.0.0.1:8080"));
  EXPECT_FALSE(origin_allowed("http://127.0.0.1:9999", "127.0.0.1:8080"));
}

}  // namespace
}  // namespace shapectl::server
