#include <shapectl/mesh/text_lines.hpp>

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include <shapectl/io/input_error.hpp>

#include "support/test_support.hpp"

namespace shapectl {
namespace {

using Comments = TextLines::Comments;

std::string error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TextLines, SkipsBlankLinesAndHashCommentsButCountsThem) {
  TextLines in("a.txt", "1 2\n\n  # note\n\t3 # four\n", Comments::Hash);
  ASSERT_TRUE(in.next());
  EXPECT_EQ(in.line(), 1);
  EXPECT_EQ(in.size(), 2u);
  ASSERT_TRUE(in.next());
  EXPECT_EQ(in.line(), 4);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0], "3");
  EXPECT_FALSE(in.next());
}

TEST(TextLines, KeepsHashWithoutComments) {
  TextLines in("a.msh", "# 2\r\n", Comments::None);
  ASSERT_TRUE(in.next());
  ASSERT_EQ(in.size(), 2u);
  EXPECT_EQ(in[0], "#");
  EXPECT_EQ(in[1], "2");
}

TEST(TextLines, ReadsNumbersStrictly) {
  TextLines in("a.txt", "+1.5 1e-999 -7 12abc 1e999 -3\n", Comments::None);
  in.next();
  EXPECT_EQ(in.real(0, "", "x"), 1.5);
  EXPECT_NEAR(in.real(1, "", "y"), 0, 1e-300);
  EXPECT_EQ(in.integer(2, "", "tag"), -7);
  EXPECT_EQ(error_of([&] { in.integer(3, "node 5", "tag"); }),
            "a.txt:1: node 5: expected an integer tag, got '12abc'");
  EXPECT_EQ(error_of([&] { in.real(3, "node 5", "z"); }),
            "a.txt:1: node 5: expected a number for z, got '12abc'");
  EXPECT_EQ(error_of([&] { in.real(4, "node 5", "z"); }),
            "a.txt:1: node 5: z is not a finite number: '1e999'");
  EXPECT_EQ(error_of([&] { in.count(5, "node count"); }),
            "a.txt:1: expected a non-negative node count, got -3");
}

TEST(TextLines, ErrorsNameTheFileAndLine) {
  TextLines in("a.txt", "1\n\n2 3\n", Comments::None);
  in.next("the first line");
  in.next("the second line");
  EXPECT_EQ(error_of([&] { in.expect_values(3, "header", "a, b, c"); }),
            "a.txt:3: header: expected 3 values (a, b, c), found 2");
  EXPECT_EQ(error_of([&] { in.next("the third line"); }),
            "a.txt:3: file ends early: expected the third line");
}

TEST(TextLines, ShownTokensAreShortAndPrintable) {
  EXPECT_EQ(shown("a\x01"
                  "b"),
            "a?b");
  EXPECT_EQ(shown(std::string(41, 'x')), std::string(40, 'x') + "...");
}

TEST(TextLines, MissingFileIsNamed) {
  test::TempDir dir;
  const auto file = dir.path() / "absent.txt";
  EXPECT_EQ(error_of([&] { read_text_file(file); }), file.string() + ": file not found");
  EXPECT_EQ(error_of([&] { read_text_file(dir.path()); }),
            dir.path().string() + ": is a directory");
}

}  // namespace
}  // namespace shapectl
