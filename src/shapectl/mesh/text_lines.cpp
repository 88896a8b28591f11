#include <shapectl/mesh/text_lines.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

std::string read_text_file(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InputError(name, "", "file not found");
  if (std::filesystem::is_directory(file, ec)) throw InputError(name, "", "is a directory");
  return read_input_file(file, max_mesh_file_bytes, "mesh");
}

std::string shown(std::string_view token) {
  std::string s(token.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return token.size() > 40 ? s + "..." : s;
}

TextLines::TextLines(std::string name, std::string text, Comments comments)
    : name_(std::move(name)), text_(std::move(text)), comments_(comments) {}

bool TextLines::next() {
  tokens_.clear();
  while (tokens_.empty() && pos_ < text_.size()) {
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    ++line_;
    std::string_view line = std::string_view(text_).substr(pos_, end - pos_);
    if (comments_ == Comments::Hash) line = line.substr(0, line.find('#'));
    pos_ = end + 1;
    for (std::size_t i = 0; i < line.size();) {
      i = line.find_first_not_of(" \t\r\v\f", i);
      if (i == std::string_view::npos) break;
      const std::size_t j = std::min(line.find_first_of(" \t\r\v\f", i), line.size());
      tokens_.push_back(line.substr(i, j - i));
      i = j;
    }
  }
  return !tokens_.empty();
}

void TextLines::next(const std::string& expected) {
  if (!next()) fail("", "file ends early: expected " + expected);
}

void TextLines::expect_values(std::size_t n, const std::string& where,
                              const std::string& what) const {
  if (size() != n)
    fail(where, "expected " + std::to_string(n) + " values (" + what + "), found " +
                    std::to_string(size()));
}

long long TextLines::integer(std::size_t i, const std::string& where,
                             const std::string& what) const {
  return integer(tokens_[i], where, what);
}

long long TextLines::integer(std::string_view token, const std::string& where,
                             const std::string& what) const {
  long long value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size())
    fail(where, "expected an integer " + what + ", got '" + shown(token) + "'");
  return value;
}

long long TextLines::count(std::size_t i, const std::string& what) const {
  const long long n = integer(i, "", what);
  if (n < 0) fail("", "expected a non-negative " + what + ", got " + std::to_string(n));
  return n;
}

double TextLines::real(std::size_t i, const std::string& where, const std::string& what) const {
  // from_chars rejects the '+' that C and Fortran writers may put before a number.
  std::string_view t = tokens_[i];
  if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec == std::errc::invalid_argument || end != t.data() + t.size())
    fail(where, "expected a number for " + what + ", got '" + shown(tokens_[i]) + "'");
  // Out of range: strtod tells overflow (inf, rejected below) from underflow (about 0).
  if (ec == std::errc::result_out_of_range) value = std::strtod(std::string(t).c_str(), nullptr);
  if (!std::isfinite(value))
    fail(where, what + " is not a finite number: '" + shown(tokens_[i]) + "'");
  return value;
}

Vec3 TextLines::point(std::size_t first, const std::string& where) const {
  return Vec3(real(first, where, "x"), real(first + 1, where, "y"), real(first + 2, where, "z"));
}

void TextLines::fail(const std::string& where, const std::string& problem) const {
  throw InputError(name_ + ":" + std::to_string(line_), where, problem);
}

}  // namespace shapectl
