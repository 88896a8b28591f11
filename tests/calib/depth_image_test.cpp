// Depth images (calib/depth_image.hpp and its files): back-projection exact to round-off, the
// renderer and the reader agreeing, PNG and NPY round trips, bad files and fields named.
#include <shapectl/calib/depth_image.hpp>

#include <gtest/gtest.h>

#include <png.h>

#include <random>

#include <shapectl/calib/depth_image_file.hpp>
#include <shapectl/calib/depth_npy.hpp>
#include <shapectl/calib/depth_png.hpp>
#include <shapectl/calib/depth_render.hpp>
#include <shapectl/calib/npy_header.hpp>
#include <shapectl/io/json_input.hpp>
#include <shapectl/mesh/box_mesh.hpp>

#include "calib/depth_views.hpp"
#include "support/test_support.hpp"

namespace shapectl {
namespace {

const PinholeIntrinsics kIntrinsics{610.5, 608.25, 319.75, 241.5};

// A tilted plane n·p = d (camera frame) seen through every pixel: the depth of each pixel's ray
// there, back-projected, lies on the plane, and in the world on the plane moved by the pose.
TEST(DepthImage, APlaneAtKnownDepthBackProjectsOntoThePlane) {
  const Vec3 n = Vec3(0.2, -0.3, 1).normalized();
  const double d = 0.7;
  DepthImage image{64, 48, {}};
  for (int v = 0; v < image.height; ++v)
    for (int u = 0; u < image.width; ++u) {
      const Vec3 ray((u - kIntrinsics.cx) / kIntrinsics.fx, (v - kIntrinsics.cy) / kIntrinsics.fy,
                     1);
      image.depth.push_back(d / n.dot(ray));
    }
  image.depth[5] = NAN;  // no reading: no point
  const Eigen::Isometry3d pose = test::look_at(Vec3(0.3, -0.5, 0.4), Vec3(0, 0, 0));
  const std::vector<Vec3> points = back_project(image, kIntrinsics, pose);
  ASSERT_EQ(points.size(), 64u * 48 - 1);
  const Vec3 n_world = pose.linear() * n;
  const double d_world = d + n_world.dot(pose.translation());
  for (const Vec3& p : points) EXPECT_NEAR(n_world.dot(p), d_world, 1e-14);
  // OpenCV axes: the principal point's pixel looks along +z, one to its right along +x.
  DepthImage centre{1, 1, {0.5}};
  const PinholeIntrinsics at_origin{100, 100, 0, 0};
  EXPECT_EQ(back_project(centre, at_origin, Eigen::Isometry3d::Identity())[0], Vec3(0, 0, 0.5));
  DepthImage right{2, 1, {NAN, 0.5}};
  EXPECT_EQ(back_project(right, at_origin, Eigen::Isometry3d::Identity())[0], Vec3(0.005, 0, 0.5));
}

// The renderer's depth of a flat face, back-projected, is on that face to round-off.
TEST(DepthImage, ARenderedFaceBackProjectsOntoTheFace) {
  const TetMesh mesh = make_box_mesh({0.2, 0.1, 0.05}, {4, 2, 1});
  Positions x(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i) x.segment<3>(3 * i) = mesh.rest_positions()[i];
  // Straight down onto the top face (z = 0.025) from 0.5 m: every hit is at depth 0.475.
  const Eigen::Isometry3d pose = test::look_at(Vec3(0, 0, 0.5), Vec3(0, 0, 0), Vec3::UnitY());
  const DepthImage image = render_depth(mesh, x, {300, 300, 31.5, 23.5}, pose, 64, 48);
  const std::vector<Vec3> points = back_project(image, {300, 300, 31.5, 23.5}, pose);
  // The face spans 0.2 × 0.1 m, the image 0.10 × 0.076 m at 0.475 m: all of it on the face.
  EXPECT_EQ(points.size(), 64u * 48);
  for (const Vec3& p : points) EXPECT_NEAR(p.z(), 0.025, 1e-15);
  // Farther off, the box is smaller than the image: pixels beside it see nothing.
  const DepthImage far = render_depth(mesh, x, {50, 50, 31.5, 23.5}, pose, 64, 48);
  const std::vector<Vec3> seen = back_project(far, {50, 50, 31.5, 23.5}, pose);
  EXPECT_GT(seen.size(), 0u);
  EXPECT_LT(seen.size(), 64u * 48);
  for (const Vec3& p : seen) EXPECT_NEAR(p.z(), 0.025, 1e-15);
}

TEST(DepthImage, PngRoundTripKeepsEverySixteenBitValue) {
  DepthPixels pixels{37, 23, {}};
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> value(0, 65535);
  for (int i = 0; i < 37 * 23; ++i) pixels.values.push_back(std::uint16_t(value(rng)));
  pixels.values[0] = 0, pixels.values[1] = 65535, pixels.values[2] = 1, pixels.values[3] = 256;
  const DepthPixels again = read_depth_png("d.png", depth_png_bytes(pixels));
  EXPECT_EQ(again.width, 37);
  EXPECT_EQ(again.height, 23);
  EXPECT_EQ(again.values, pixels.values);
  // value × scale, 0 → no reading.
  const DepthImage metres = depth_from_pixels(again, 0.001);
  EXPECT_TRUE(std::isnan(metres.depth[0]));
  EXPECT_DOUBLE_EQ(metres.depth[1], 65.535);
  EXPECT_EQ(pixels_from_depth(metres, 0.001).values, pixels.values);
}

TEST(DepthImage, NpyRoundTripKeepsFloat32Values) {
  DepthImage image{5, 3, {}};
  for (int i = 0; i < 15; ++i) image.depth.push_back(0.4 + 0.01 * i);
  image.depth[4] = NAN;
  const DepthImage again = read_depth_npy("d.npy", depth_npy_bytes(image), 1);
  EXPECT_EQ(again.width, 5);
  EXPECT_EQ(again.height, 3);
  for (int i = 0; i < 15; ++i)
    if (i == 4) EXPECT_TRUE(std::isnan(again.depth[i]));
    else EXPECT_EQ(again.depth[i], double(float(image.depth[i])));
}

// An 8-bit or colour PNG (libpng's simplified writer) for the refusals.
std::string png_of(png_uint_32 format, int width, int height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = width, image.height = height, image.format = format;
  std::vector<png_byte> buffer(PNG_IMAGE_SIZE(image), 7);
  png_alloc_size_t size = 0;
  EXPECT_TRUE(png_image_write_to_memory(&image, nullptr, &size, 0, buffer.data(), 0, nullptr));
  std::string bytes(size, '\0');
  EXPECT_TRUE(png_image_write_to_memory(&image, bytes.data(), &size, 0, buffer.data(), 0, nullptr));
  return bytes;
}

TEST(DepthImage, FilesThatAreNotDepthImagesAreRefusedNamingTheProblem) {
  const auto error_of = [](auto read) { return test::input_error_of(read); };
  EXPECT_EQ(error_of([] { read_depth_png("d.png", png_of(PNG_FORMAT_GRAY, 4, 4)); }),
            "d.png: expected a 16-bit grayscale PNG, got 8-bit grayscale");
  EXPECT_EQ(error_of([] { read_depth_png("d.png", png_of(PNG_FORMAT_RGB, 4, 4)); }),
            "d.png: expected a 16-bit grayscale PNG, got 8-bit RGB");
  EXPECT_EQ(error_of([] { read_depth_png("d.png", "GIF89a.........."); }),
            "d.png: expected the PNG signature (not a PNG file)");
  std::string cut = depth_png_bytes({8, 8, std::vector<std::uint16_t>(64, 500)});
  cut.resize(cut.size() / 2);
  EXPECT_NE(error_of([&] { read_depth_png("d.png", cut); }).find("d.png: "), std::string::npos);
  // The size is refused from the header, before the pixels are allocated.
  const DepthPixels huge{4096, 2048, std::vector<std::uint16_t>(4096u * 2048)};
  EXPECT_EQ(error_of([&] { read_depth_png("d.png", depth_png_bytes(huge)); }),
            "d.png: 4096 x 2048 pixels, more than the limit of 4194304 pixels");

  const std::string points = npy_header_bytes("<i4", {2, 2}) + std::string(16, '\0');
  EXPECT_EQ(error_of([&] { read_depth_npy("d.npy", points, 1); }),
            "d.npy: header 'descr': expected '<f4' or '<f8' (little-endian float32 or float64), "
            "got '<i4'");
  const std::string cube = npy_header_bytes("<f4", {2, 2, 2}) + std::string(32, '\0');
  EXPECT_EQ(error_of([&] { read_depth_npy("d.npy", cube, 1); }),
            "d.npy: header 'shape': expected (height, width), got (2, 2, 2)");
  const std::string wide = npy_header_bytes("<f4", {1u << 20, 1u << 20});
  EXPECT_EQ(error_of([&] { read_depth_npy("d.npy", wide, 1); }),
            "d.npy: header 'shape': expected at least 1 and at most 4194304 pixels, got "
            "(1048576, 1048576)");
  const std::string short_data = npy_header_bytes("<f4", {2, 2}) + std::string(12, '\0');
  EXPECT_EQ(error_of([&] { read_depth_npy("d.npy", short_data, 1); }),
            "d.npy: data: expected 4 values of 4 bytes (16 bytes) after the header, got 12 bytes");
}

// The frame's "depth_image" field (calib/depth_image_file.hpp), a good one first.
class DepthImageField : public ::testing::Test {
 protected:
  test::TempDir dir;
  nlohmann::json good = {{"file", "d.png"},
                         {"scale", 0.001},
                         {"intrinsics", {{"fx", 100}, {"fy", 100}, {"cx", 1.5}, {"cy", 1.5}}},
                         {"camera_pose", {{"position", {0, 0, 1}}, {"rpy", {M_PI, 0, 0}}}}};
  void SetUp() override {
    dir.write("d.png", depth_png_bytes({4, 4, std::vector<std::uint16_t>(16, 800)}));
  }
  DepthImageObservation read(const nlohmann::json& j) const {
    return read_depth_image(JsonInput(j, (dir.path() / "obs.json").string(), "depth_image"));
  }
  std::string error_of(const nlohmann::json& j) const {
    return test::input_error_of([&] { read(j); });
  }
};

TEST_F(DepthImageField, PointsArePlacedByTheCameraPoseAndCropped) {
  // Turned by π about x, 1 m up: looking straight down, the image's 0.8 m is z = 0.2.
  DepthImageObservation seen = read(good);
  ASSERT_EQ(seen.points.size(), 16u);
  for (const Vec3& p : seen.points) EXPECT_NEAR(p.z(), 0.2, 1e-15);
  EXPECT_EQ(seen.camera.index, 0);
  EXPECT_EQ(seen.camera.position, Vec3(0, 0, 1));
  nlohmann::json cropped = good;
  cropped["crop"] = {{"box", {{"min", {0, -1, -1}}, {"max", {1, 1, 1}}}}};
  cropped["camera"] = 2;
  seen = read(cropped);
  EXPECT_EQ(seen.points.size(), 8u);  // x = ±0.004, ±0.012: half the columns
  EXPECT_EQ(seen.camera.index, 2);
  nlohmann::json strided = good;
  strided["stride"] = 2;
  EXPECT_EQ(read(strided).points.size(), 4u);
}

TEST_F(DepthImageField, BadFieldsAreNamed) {
  const std::string at = (dir.path() / "obs.json").string() + ": depth_image";
  auto without = [&](const char* key) {
    nlohmann::json j = good;
    j.erase(key);
    return j;
  };
  auto with = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json j = good;
    j[nlohmann::json::json_pointer(pointer)] = value;
    return j;
  };
  EXPECT_EQ(error_of(without("intrinsics")), at + ".intrinsics: missing key");
  EXPECT_EQ(error_of(with("/intrinsics/fx", 0)),
            at + ".intrinsics.fx: expected a positive number, got 0");
  EXPECT_EQ(error_of(with("/intrinsics", {{"fx", 1}, {"fy", 1}, {"cx", 0}})),
            at + ".intrinsics.cy: missing key");
  EXPECT_EQ(error_of(with("/scale", -0.001)),
            at + ".scale: expected a positive number, got -0.001");
  EXPECT_EQ(error_of(without("scale")),
            at + ": missing \"scale\" (m per unit of the PNG's values, e.g. 0.001)");
  EXPECT_EQ(error_of(with("/crop", {{"box", {{"min", {0, 0, 1}}, {"max", {1, 1, 0}}}}})),
            at + ".crop.box.max: expected a corner not below min in any axis, got [1,1,0]");
  EXPECT_EQ(
      error_of(with("/file", "d.jpg")),
      at + ".file: expected a .png (16-bit grayscale) or .npy (2-D float) file, got \"d.jpg\"");
  EXPECT_NE(error_of(with("/file", "none.png")).find(at + ".file: cannot read the depth image: "),
            std::string::npos);
  EXPECT_EQ(error_of(with("/camera", 16)),
            at + ".camera: expected a whole number from 0 to 15, got 16");
  EXPECT_EQ(error_of(with("/stride", 0)),
            at + ".stride: expected a whole number from 1 to 1000, got 0");
}

}  // namespace
}  // namespace shapectl
