#include <shapectl/io/json_input.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace shapectl {

JsonInput JsonInput::load(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot open file");
  std::stringstream text;
  text << in.rdbuf();
  try {
    return JsonInput(nlohmann::json::parse(text.str()), file.string());
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann reports a byte offset; turn it into a line number.
    const std::string s = text.str();
    const std::size_t end = std::min<std::size_t>(e.byte, s.size());
    const long line = 1 + std::count(s.begin(), s.begin() + static_cast<long>(end), '\n');
    throw InputError(file.string() + ":" + std::to_string(line), "",
                     std::string("invalid JSON (") + e.what() + ")");
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string(), "", std::string("invalid JSON (") + e.what() + ")");
  }
}

JsonInput::JsonInput(nlohmann::json value, std::string source, std::string path)
    : value_(std::move(value)), source_(std::move(source)), path_(std::move(path)) {}

std::filesystem::path JsonInput::directory() const {
  return std::filesystem::path(source_).parent_path();
}

std::string JsonInput::child_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

std::string JsonInput::shown() const {
  std::string s = value_.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
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
  if (it == value_.end())
    throw InputError(source_, child_path(key), "missing key");
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

std::vector<double> JsonInput::numbers() const {
  std::vector<double> out(size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = at(i).number();
  return out;
}

}  // namespace shapectl
