#include <gtest/gtest.h>

#include <shapectl/io/ascii_case.hpp>

namespace shapectl {
namespace {

TEST(AsciiCase, LowersOnlyAsciiLetters) {
  EXPECT_EQ(ascii_lowercase("Host: EXAMPLE.org:8080"), "host: example.org:8080");
  // Bytes outside A–Z stay as they are, UTF-8 included ("Ä" is two bytes, neither A–Z).
  EXPECT_EQ(ascii_lowercase("\xC3\x84Z[@`"), "\xC3\x84z[@`");
  EXPECT_EQ(ascii_lowercase(""), "");
}

TEST(AsciiCase, TheExtensionOfAFileInLowerCase) {
  EXPECT_EQ(lowercase_extension("meshes/Link.STL"), ".stl");
  EXPECT_EQ(lowercase_extension("cloud.Ply"), ".ply");
  EXPECT_EQ(lowercase_extension("archive.tar.GZ"), ".gz");
  EXPECT_EQ(lowercase_extension("README"), "");
  EXPECT_EQ(lowercase_extension("dir.D/file"), "");
}

}  // namespace
}  // namespace shapectl
