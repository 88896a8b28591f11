#pragma once
// The `${...}` expressions of xacro files: the Python subset robot descriptions use (numbers,
// strings, booleans, arithmetic, comparisons, and/or/not, `a if c else b`, pi and math functions).
// Values follow xacro's Python typing, so "3.7000" evaluates to 3.7 and prints as "3.7".
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace shapectl {

struct XacroValue {
  enum class Kind { integer, real, string, boolean };
  Kind kind = Kind::string;
  double number = 0;  // integer, real and boolean (0 or 1)
  std::string text;   // string

  static XacroValue integer(double v) { return {Kind::integer, v, {}}; }
  static XacroValue real(double v) { return {Kind::real, v, {}}; }
  static XacroValue boolean(bool v) { return {Kind::boolean, v ? 1.0 : 0.0, {}}; }
  static XacroValue string(std::string s) { return {Kind::string, 0, std::move(s)}; }
  bool is_number() const { return kind != Kind::string; }
};

// A malformed or ill-typed expression, or an undefined name; the expander adds file:line.
class XacroExpressionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The value of a property or macro parameter, or nullopt when `name` is not defined.
using XacroLookup = std::function<std::optional<XacroValue>(const std::string& name)>;

// Evaluates the text between "${" and "}". Throws XacroExpressionError.
XacroValue evaluate_xacro_expression(std::string_view expression, const XacroLookup& lookup);

// How xacro types a property's text: 'quoted' is the string inside the quotes, an integer or
// real literal is a number, true/false/True/False a boolean (text with '_' stays a string).
XacroValue xacro_literal(const std::string& text);

// The text Python's str() gives: 3 → "3", 3.0 → "3.0", 1e-05, True; strings as they are.
std::string xacro_text(const XacroValue& value);

// Python truth: non-zero numbers and non-empty strings.
bool xacro_truth(const XacroValue& value);

}  // namespace shapectl
