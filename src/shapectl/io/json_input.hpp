#pragma once
// Strict reading of JSON input files: every value knows its file and path
// ("scene.json: object.material.mu"), so errors say where and what was expected.
#include <Eigen/Core>
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>

namespace shapectl {

// Bounds on JSON text, checked before parsing: the parser and dump() recurse per level.
struct JsonLimits {
  std::size_t max_bytes = max_json_file_bytes;
  int max_depth = 64;  // nested arrays and objects; scenes use 5
};

// Byte offset where arrays/objects first nest deeper than `max_depth`, or npos: one pass over
// the text, no recursion (strings and their escapes skipped), so safe before any parser.
std::size_t json_too_deep_at(std::string_view text, int max_depth);

// Parses JSON text strictly: size and nesting within `limits`, no key twice in an object.
// Throws InputError naming `source` (and the line or the key's path): "scene.json:12: invalid
// JSON (...)", "scene.json:3: JSON nested deeper than 64 levels", "scene.json: object.mesh:
// duplicate key (each key may appear once)". Usable for any JSON input, files or messages.
nlohmann::json parse_json_text(std::string_view text, const std::string& source,
                               const JsonLimits& limits = {});

class JsonInput {
 public:
  // Reads (read_input_file, max_json_file_bytes) and parses (parse_json_text) a file; a
  // missing, non-regular or oversize file or bad JSON is an InputError naming it.
  static JsonInput load(const std::filesystem::path& file);
  JsonInput(nlohmann::json value, std::string source, std::string path = "");

  const nlohmann::json& raw() const { return value_; }
  const std::string& source() const { return source_; }
  const std::string& path() const { return path_; }
  // The directory of the file this came from, for resolving relative paths.
  std::filesystem::path directory() const;
  // The file this string names: relative to directory() unless absolute. A file that does not
  // exist is an InputError naming the field, the name as written and how it was resolved:
  // "scene.json: robot.urdf: no file 'arm.urdf' (relative to the folder of scene.json, /a/b:
  // /a/b/arm.urdf)".
  std::filesystem::path file_path() const;

  bool is_object() const { return value_.is_object(); }
  bool is_array() const { return value_.is_array(); }
  bool is_string() const { return value_.is_string(); }
  bool is_number() const { return value_.is_number(); }

  bool has(std::string_view key) const;
  JsonInput at(std::string_view key) const;  // required member of an object
  JsonInput at(std::size_t index) const;     // element of an array
  std::size_t size() const;                  // length of an array (error if not an array)
  std::vector<std::string> keys() const;     // members of an object, in file order
  // Every member must be one of `known`; a typo must never silently change the physics.
  void expect_only(std::initializer_list<std::string_view> known) const;
  void expect_only(const std::vector<std::string>& known) const;

  double number() const;                    // finite
  double positive() const;                  // finite, > 0
  double non_negative() const;              // finite, >= 0
  long integer() const;                     // a whole number
  long integer_in(long lo, long hi) const;  // lo <= value <= hi
  // lo <= value <= hi; `unit` ("m", "Pa") is shown with the range in the message.
  double number_in(double lo, double hi, const std::string& unit) const;
  // [x, y, z] with |(x, y, z)| <= radius; `what` names it ("a point", "a gravity vector").
  Eigen::Vector3d vec3_within(double radius, const std::string& what,
                              const std::string& unit) const;
  bool boolean() const;
  std::string string() const;
  Eigen::Vector3d vec3() const;         // [x, y, z], finite
  std::vector<double> numbers() const;  // array of finite numbers

  // Throws InputError "<source>: <path>: expected <expected>, got <what is there>".
  [[noreturn]] void fail(const std::string& expected) const;
  [[noreturn]] void fail_problem(const std::string& problem) const;

 private:
  std::string child_path(std::string_view key) const;
  std::string shown() const;
  nlohmann::json value_;
  std::string source_;
  std::string path_;
};

}  // namespace shapectl
