#include <shapectl/calib/npy_header.hpp>

#include <charconv>
#include <optional>
#include <string_view>

#include <shapectl/calib/little_endian.hpp>
#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

namespace {

struct NpyHeader {
  std::optional<std::string> descr;
  std::optional<bool> fortran_order;
  std::optional<std::vector<std::uint64_t>> shape;
};

// The header is a Python dict literal, e.g. "{'descr': '<f8', 'fortran_order': False,
// 'shape': (10, 3), }" padded with spaces and a newline. Reads just that much Python.
class NpyHeaderParser {
 public:
  NpyHeaderParser(const std::string& name, std::string_view text) : name_(name), text_(text) {}

  NpyHeader parse() {
    NpyHeader h;
    expect('{');
    while (!eat('}')) {
      const std::string key = quoted();
      expect(':');
      if (key == "descr" && !h.descr) {
        h.descr = quoted();
      } else if (key == "fortran_order" && !h.fortran_order) {
        h.fortran_order = boolean();
      } else if (key == "shape" && !h.shape) {
        h.shape = tuple();
      } else {
        fail("the key 'descr', 'fortran_order' or 'shape', each once");
      }
      if (!eat(',')) {
        expect('}');
        break;
      }
    }
    skip_space();
    if (pos_ != text_.size()) fail("only spaces after the dict");
    if (!h.descr || !h.fortran_order || !h.shape)
      throw InputError(name_, "header", "expected the keys 'descr', 'fortran_order' and 'shape'");
    return h;
  }

 private:
  void skip_space() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\n')) ++pos_;
  }
  bool eat(char c) {
    skip_space();
    if (pos_ >= text_.size() || text_[pos_] != c) return false;
    ++pos_;
    return true;
  }
  void expect(char c) {
    if (!eat(c)) fail(std::string("'") + c + "'");
  }
  std::string quoted() {
    skip_space();
    const char quote = pos_ < text_.size() ? text_[pos_] : 0;
    if (quote != '\'' && quote != '"') fail("a quoted string");
    const std::size_t end = text_.find(quote, pos_ + 1);
    if (end == std::string_view::npos) fail("the end of a quoted string");
    const std::string s(text_.substr(pos_ + 1, end - pos_ - 1));
    pos_ = end + 1;
    return s;
  }
  bool boolean() {
    skip_space();
    for (const bool value : {false, true}) {
      const std::string_view word = value ? "True" : "False";
      if (text_.substr(pos_, word.size()) == word) {
        pos_ += word.size();
        return value;
      }
    }
    fail("True or False");
  }
  // (a, b, ...) of non-negative integers, a trailing comma allowed.
  std::vector<std::uint64_t> tuple() {
    expect('(');
    std::vector<std::uint64_t> out;
    while (!eat(')')) {
      skip_space();
      std::uint64_t value = 0;
      const auto [end, ec] =
          std::from_chars(text_.data() + pos_, text_.data() + text_.size(), value);
      if (ec != std::errc()) fail("a non-negative integer of a shape");
      pos_ = static_cast<std::size_t>(end - text_.data());
      out.push_back(value);
      if (out.size() > 32) fail("a shape of at most 32 dimensions");
      if (!eat(',')) {
        expect(')');
        break;
      }
    }
    return out;
  }
  [[noreturn]] void fail(const std::string& expected) const {
    throw InputError(name_, "header",
                     "expected " + expected + " at character " + std::to_string(pos_) + " of \"" +
                         bounded_preview(text_, 120) + "\"");
  }

  const std::string& name_;
  std::string_view text_;
  std::size_t pos_ = 0;
};

}  // namespace

std::string npy_shape_text(const std::vector<std::uint64_t>& shape) {
  std::string s;
  for (const std::uint64_t n : shape) s += (s.empty() ? "" : ", ") + std::to_string(n);
  return "(" + s + (shape.size() == 1 ? ",)" : ")");
}

NpyArray read_npy_header(const std::string& name, const std::string& bytes) {
  if (!bytes.starts_with("\x93NUMPY") || bytes.size() < 10)
    throw InputError(name, "", "expected the NumPy magic string \\x93NUMPY (not a .npy file)");
  const int major = static_cast<unsigned char>(bytes[6]);
  const int minor = static_cast<unsigned char>(bytes[7]);
  if ((major != 1 && major != 2) || minor != 0)
    throw InputError(name, "version",
                     "expected format 1.0 or 2.0, got " + std::to_string(major) + "." +
                         std::to_string(minor));
  // Format 1.0 gives the header's length in 2 bytes, 2.0 in 4.
  const std::size_t header_start = major == 1 ? 10 : 12;
  if (bytes.size() < header_start) throw InputError(name, "header", "the file ends inside it");
  const std::size_t header_length = major == 1 ? read_little_endian<std::uint16_t>(&bytes[8])
                                               : read_little_endian<std::uint32_t>(&bytes[8]);
  if (header_length > bytes.size() - header_start)
    throw InputError(name, "header",
                     "the file ends inside it (" + std::to_string(header_length) +
                         " bytes announced)");
  const NpyHeader header =
      NpyHeaderParser(name, std::string_view(bytes).substr(header_start, header_length)).parse();

  if (*header.fortran_order)
    throw InputError(name, "header 'fortran_order'", "False (C order)", "True");
  return {*header.descr, *header.shape, header_start + header_length};
}

std::string npy_header_bytes(const std::string& descr, const std::vector<std::uint64_t>& shape) {
  std::string dict = "{'descr': '" + descr +
                     "', 'fortran_order': False, 'shape': " + npy_shape_text(shape) + ", }";
  // Format 1.0: magic, version, a 2-byte length, the dict padded with spaces to a multiple of 64
  // bytes in all, ending in a newline.
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string out = "\x93NUMPY";
  out += '\x01', out += '\x00';
  out += static_cast<char>(dict.size() & 0xff), out += static_cast<char>(dict.size() >> 8);
  return out + dict;
}

}  // namespace shapectl
