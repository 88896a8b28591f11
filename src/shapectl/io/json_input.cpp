#include <shapectl/io/json_input.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <sstream>

#include <shapectl/io/input_file.hpp>

namespace shapectl {

namespace {

// The line holding byte `at` of `text`.
long line_at(std::string_view text, std::size_t at) {
  at = std::min(at, text.size());
  return 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n');
}

// Tracks where the parser is ("object.mesh.box", "grips[1]") and refuses a key an object
// already has: with nlohmann's default the last one would silently win. Copies share the
// position (nlohmann keeps a copy), so a failed parse can say where it stopped.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& source) : source_(source) {}

  // The path of the value being read when parsing stopped ("loads[0].force[2]"): in an array,
  // the element after the last one counted (it never parsed).
  std::string failed_value_path() const { return path(1); }

  bool operator()(int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        count_element();
        frames_->push_back({event == Event::object_start, {}, {}, -1});
        break;
      case Event::object_end:
      case Event::array_end:
        if (!frames_->empty()) frames_->pop_back();
        break;
      case Event::key: {
        Frame& top = frames_->back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          throw InputError(source_, path(), "duplicate key (each key may appear once)");
        break;
      }
      case Event::value: count_element(); break;
    }
    return true;
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;  // the member being read
    long index;       // the element being read
  };
  void count_element() {
    if (!frames_->empty() && !frames_->back().object) ++frames_->back().index;
  }
  // `pending`: added to the innermost array's index.
  std::string path(long pending = 0) const {
    std::string out;
    for (std::size_t k = 0; k < frames_->size(); ++k) {
      const Frame& f = (*frames_)[k];
      const long index = f.index + (k + 1 == frames_->size() ? pending : 0);
      out += f.object ? (out.empty() ? "" : ".") + bounded_preview(f.key)
                      : "[" + std::to_string(index) + "]";
    }
    return out;
  }
  const std::string& source_;
  std::shared_ptr<std::vector<Frame>> frames_ = std::make_shared<std::vector<Frame>>();
};

}  // namespace

std::size_t json_too_deep_at(std::string_view text, int max_depth) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::string_view::npos;
}

nlohmann::json parse_json_text(std::string_view text, const std::string& source,
                               const JsonLimits& limits) {
  if (text.size() > limits.max_bytes)
    throw InputError(source, "",
                     "longer than the " + std::to_string(limits.max_bytes) +
                         " byte limit for JSON");
  if (const std::size_t at = json_too_deep_at(text, limits.max_depth); at != std::string_view::npos)
    throw InputError(source + ":" + std::to_string(line_at(text, at)), "",
                     "JSON nested deeper than " + std::to_string(limits.max_depth) + " levels");
  const DuplicateKeyCheck check(source);
  try {
    return nlohmann::json::parse(text.begin(), text.end(), check);
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann reports a byte offset; turn it into a line number. Its "last read" token can
    // be the whole rest of the file: the message is cut.
    throw InputError(source + ":" + std::to_string(line_at(text, e.byte)), "",
                     "invalid JSON (" + bounded_preview(e.what(), 200) + ")");
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond a double's range (1e999) would be infinite: named where it stands.
    throw InputError(source, check.failed_value_path(),
                     "expected a finite number, got one out of range (" +
                         bounded_preview(e.what(), 200) + ")");
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source, "", "invalid JSON (" + bounded_preview(e.what(), 200) + ")");
  }
}

JsonInput JsonInput::load(const std::filesystem::path& file) {
  const std::string text = read_input_file(file, max_json_file_bytes, "JSON");
  return JsonInput(parse_json_text(text, file.string()), file.string());
}

JsonInput::JsonInput(nlohmann::json value, std::string source, std::string path)
    : value_(std::move(value)), source_(std::move(source)), path_(std::move(path)) {}

std::filesystem::path JsonInput::directory() const {
  return std::filesystem::path(source_).parent_path();
}

std::filesystem::path JsonInput::file_path() const {
  const std::string name = string();
  const std::filesystem::path file = directory() / name;  // an absolute name stays as it is
  std::error_code error;
  // Only a file known to be absent; any other trouble (permissions) its reader reports.
  if (std::filesystem::exists(file, error) || error) return file;
  const std::string shown = bounded_preview(name, 1000);  // a path, not the usual 80 bytes
  if (std::filesystem::path(name).is_absolute()) fail_problem("no file '" + shown + "'");
  fail_problem("no file '" + shown + "' (relative to the folder of " + source_ + ", " +
               resolved_path(directory()).string() + ": " + resolved_path(file).string() + ")");
}

std::string JsonInput::child_path(std::string_view key) const {
  // Keys come from the input: a path shows at most 80 bytes of each.
  const std::string shown_key = bounded_preview(key);
  return path_.empty() ? shown_key : path_ + "." + shown_key;
}

namespace {

// A JSON string literal of at most about `max_chars` bytes.
std::string quoted_preview(std::string_view s, std::size_t max_chars) {
  return nlohmann::json(bounded_preview(s, max_chars))
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Appends a compact rendering of `v` to `out`, stopping soon after `out` reaches `budget`
// bytes: no recursion deeper than a few levels and no work proportional to a huge value.
void append_preview(const nlohmann::json& v, std::string& out, std::size_t budget, int depth) {
  if (out.size() > budget) return;
  if (v.is_string()) {
    out += quoted_preview(v.get_ref<const std::string&>(), budget - out.size() + 1);
  } else if (!v.is_structured()) {
    out += v.dump();
  } else if (depth >= 4) {
    out += v.is_object() ? "{...}" : "[...]";
  } else {
    out += v.is_object() ? '{' : '[';
    bool first = true;
    for (auto it = v.begin(); it != v.end() && out.size() <= budget; ++it) {
      if (!first) out += ',';
      first = false;
      if (v.is_object()) out += quoted_preview(it.key(), budget) + ':';
      append_preview(*it, out, budget, depth + 1);
    }
    out += v.is_object() ? '}' : ']';
  }
}

}  // namespace

std::string JsonInput::shown() const {
  std::string s;
  append_preview(value_, s, 60, 0);
  if (s.size() > 60) {
    std::size_t end = 57;  // not inside a UTF-8 character
    while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
    s = s.substr(0, end) + "...";
  }
  return s;
}

void JsonInput::fail(const std::string& expected) const {
  throw InputError(source_, path_.empty() ? "(top level)" : path_, expected, shown());
}

void JsonInput::fail_problem(const std::string& problem) const {
  throw InputError(source_, path_.empty() ? "(top level)" : path_, problem);
}

bool JsonInput::has(std::string_view key) const {
  return value_.is_object() && value_.contains(key);
}

JsonInput JsonInput::at(std::string_view key) const {
  if (!value_.is_object()) fail("an object");
  auto it = value_.find(key);
  if (it == value_.end()) throw InputError(source_, child_path(key), "missing key");
  return JsonInput(*it, source_, child_path(key));
}

JsonInput JsonInput::at(std::size_t index) const {
  if (!value_.is_array()) fail("an array");
  if (index >= value_.size()) fail_problem("index " + std::to_string(index) + " out of range");
  return JsonInput(value_[index], source_, path_ + "[" + std::to_string(index) + "]");
}

std::size_t JsonInput::size() const {
  if (!value_.is_array()) fail("an array");
  return value_.size();
}

std::vector<std::string> JsonInput::keys() const {
  if (!value_.is_object()) fail("an object");
  std::vector<std::string> out;
  for (auto it = value_.begin(); it != value_.end(); ++it) out.push_back(it.key());
  return out;
}

void JsonInput::expect_only(const std::vector<std::string>& known) const {
  if (!value_.is_object()) fail("an object");
  for (auto it = value_.begin(); it != value_.end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    throw InputError(source_, child_path(it.key()), "unknown key; known: " + list);
  }
}

void JsonInput::expect_only(std::initializer_list<std::string_view> known) const {
  expect_only(std::vector<std::string>(known.begin(), known.end()));
}

double JsonInput::number() const {
  if (!value_.is_number()) fail("a number");
  const double v = value_.get<double>();
  if (!std::isfinite(v)) fail("a finite number");
  return v;
}

double JsonInput::positive() const {
  const double v = number();
  if (!(v > 0)) fail("a positive number");
  return v;
}

double JsonInput::non_negative() const {
  const double v = number();
  if (!(v >= 0)) fail("a non-negative number");
  return v;
}

long JsonInput::integer() const {
  if (!value_.is_number()) fail("a whole number");
  const double v = value_.get<double>();
  if (!std::isfinite(v) || v != std::floor(v) || std::abs(v) > 9e15) fail("a whole number");
  return static_cast<long>(v);
}

long JsonInput::integer_in(long lo, long hi) const {
  const long v = integer();
  if (v < lo || v > hi)
    fail("a whole number from " + std::to_string(lo) + " to " + std::to_string(hi));
  return v;
}

bool JsonInput::boolean() const {
  if (!value_.is_boolean()) fail("true or false");
  return value_.get<bool>();
}

std::string JsonInput::string() const {
  if (!value_.is_string()) fail("a string");
  return value_.get<std::string>();
}

Eigen::Vector3d JsonInput::vec3() const {
  if (!value_.is_array() || value_.size() != 3) fail("an array of 3 numbers");
  return {at(std::size_t{0}).number(), at(1).number(), at(2).number()};
}

double JsonInput::number_in(double lo, double hi, const std::string& unit) const {
  const double v = number();
  if (!(v >= lo && v <= hi)) {
    std::ostringstream range;
    range << "a number from " << lo << " to " << hi << (unit.empty() ? "" : " " + unit);
    fail(range.str());
  }
  return v;
}

Eigen::Vector3d JsonInput::vec3_within(double radius, const std::string& what,
                                       const std::string& unit) const {
  const Eigen::Vector3d v = vec3();
  if (!(v.norm() <= radius)) {
    std::ostringstream expected;
    expected << what << " of length at most " << radius << " " << unit;
    fail(expected.str());
  }
  return v;
}

std::vector<double> JsonInput::numbers() const {
  std::vector<double> out(size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = at(i).number();
  return out;
}

}  // namespace shapectl
