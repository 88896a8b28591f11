#pragma once
// Line-by-line reading of text mesh formats (MSH, TetGen, OBJ, OFF, ASCII STL) with strict
// number parsing and errors that name "file:line".
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/types.hpp>

namespace shapectl {

// The whole file as bytes. Throws InputError naming the file: "file not found",
// "is a directory", "cannot open file", "not a regular file" (a FIFO, a device) or larger than
// max_mesh_file_bytes.
std::string read_text_file(const std::filesystem::path& file);

// A token as it may appear in a message: at most 40 characters (then "..."), unprintable
// bytes as '?', so a binary or garbled file cannot flood or corrupt the message.
std::string shown(std::string_view token);

// The text's lines that hold data, one at a time, split at whitespace; blank lines (and,
// with Comments::Hash, everything from '#' to the end of a line) are skipped.
// Every error is an InputError whose source is "name:line" of the current line.
class TextLines {
 public:
  enum class Comments { None, Hash };

  // `name` is the file as messages show it; line numbers count from 1.
  TextLines(std::string name, std::string text, Comments comments);

  const std::string& name() const { return name_; }
  int line() const { return line_; }  // 0 before the first next()
  std::size_t size() const { return tokens_.size(); }
  std::string_view operator[](std::size_t i) const { return tokens_[i]; }

  // Moves to the next line holding data; false at the end of the text.
  bool next();
  // Moves to the next line holding data, which must exist: `expected` says what for.
  void next(const std::string& expected);

  // The current line must hold exactly `n` values, described as `what` ("node tag, x, y, z").
  void expect_values(std::size_t n, const std::string& where, const std::string& what) const;

  // Token i (or `token`) as a whole integer; `what` names it in the message.
  long long integer(std::size_t i, const std::string& where, const std::string& what) const;
  long long integer(std::string_view token, const std::string& where,
                    const std::string& what) const;
  // Token i as an integer >= 0.
  long long count(std::size_t i, const std::string& what) const;
  // Token i as a finite number; a leading '+' is accepted, underflow reads as about 0.
  double real(std::size_t i, const std::string& where, const std::string& what) const;
  // Tokens first..first+2 as x, y, z.
  Vec3 point(std::size_t first, const std::string& where) const;

  // Throws InputError("name:line", where, problem).
  [[noreturn]] void fail(const std::string& where, const std::string& problem) const;

 private:
  std::string name_;
  std::string text_;
  Comments comments_;
  std::size_t pos_ = 0;
  int line_ = 0;
  std::vector<std::string_view> tokens_;  // views into text_
};

}  // namespace shapectl
