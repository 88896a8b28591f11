#include <shapectl/robot/xacro_expression.hpp>

#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

namespace shapectl {

namespace {

constexpr int max_nesting = 100;  // parentheses and unary operators: bounds the recursion

struct Token {
  enum class Kind { number, string, name, op, end };
  Kind kind;
  std::string text;
};

bool is_name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

std::vector<Token> tokenize(std::string_view s) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (std::isdigit(static_cast<unsigned char>(c)) ||
               (c == '.' && i + 1 < s.size() &&
                std::isdigit(static_cast<unsigned char>(s[i + 1])))) {
      std::size_t j = i;
      while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.')) ++j;
      if (j < s.size() && (s[j] == 'e' || s[j] == 'E')) {
        std::size_t k = j + 1;
        if (k < s.size() && (s[k] == '+' || s[k] == '-')) ++k;
        if (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k]))) {
          j = k;
          while (j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]))) ++j;
        }
      }
      tokens.push_back({Token::Kind::number, std::string(s.substr(i, j - i))});
      i = j;
    } else if (is_name_start(c)) {
      std::size_t j = i;
      while (j < s.size() && is_name_char(s[j])) ++j;
      tokens.push_back({Token::Kind::name, std::string(s.substr(i, j - i))});
      i = j;
    } else if (c == '\'' || c == '"') {
      const std::size_t end = s.find(c, i + 1);
      if (end == std::string_view::npos) throw XacroExpressionError("unterminated string literal");
      tokens.push_back({Token::Kind::string, std::string(s.substr(i + 1, end - i - 1))});
      i = end + 1;
    } else {
      static const char* const two_char[] = {"**", "//", "==", "!=", "<=", ">="};
      std::string op(1, c);
      for (const char* t : two_char)
        if (s.substr(i, 2) == t) op = t;
      if (op.size() == 1 && std::string_view("+-*/%()<>,.").find(c) == std::string_view::npos)
        throw XacroExpressionError(std::string("unexpected character '") + c + "'");
      tokens.push_back({Token::Kind::op, op});
      i += op.size();
    }
  }
  tokens.push_back({Token::Kind::end, ""});
  return tokens;
}

bool is_integral(const XacroValue& v) {
  return v.kind == XacroValue::Kind::integer || v.kind == XacroValue::Kind::boolean;
}

std::string kind_name(const XacroValue& v) {
  switch (v.kind) {
    case XacroValue::Kind::integer: return "integer";
    case XacroValue::Kind::real: return "number";
    case XacroValue::Kind::boolean: return "boolean";
    default: return "string '" + v.text + "'";
  }
}

double number_of(const XacroValue& v, const std::string& op) {
  if (!v.is_number())
    throw XacroExpressionError("'" + op + "' expects numbers, got " + kind_name(v));
  return v.number;
}

XacroValue arithmetic(const std::string& op, const XacroValue& a, const XacroValue& b) {
  if (op == "+" && a.kind == XacroValue::Kind::string && b.kind == XacroValue::Kind::string)
    return XacroValue::string(a.text + b.text);
  const double x = number_of(a, op), y = number_of(b, op);
  const bool integers = is_integral(a) && is_integral(b);
  auto result = [&](double v) { return integers ? XacroValue::integer(v) : XacroValue::real(v); };
  if (op == "+") return result(x + y);
  if (op == "-") return result(x - y);
  if (op == "*") return result(x * y);
  if ((op == "/" || op == "//" || op == "%") && y == 0)
    throw XacroExpressionError("division by zero");
  if (op == "/") return XacroValue::real(x / y);
  if (op == "//") return result(std::floor(x / y));
  if (op == "%") return result(x - y * std::floor(x / y));  // Python's sign convention
  // "**": an integer to a non-negative integer power stays an integer, as in Python.
  if (integers && y >= 0) return XacroValue::integer(std::pow(x, y));
  if (x < 0 && y != std::floor(y))
    throw XacroExpressionError("negative number to a fractional power");
  return XacroValue::real(std::pow(x, y));
}

bool compare(const std::string& op, const XacroValue& a, const XacroValue& b) {
  if (a.is_number() && b.is_number()) {
    if (op == "==") return a.number == b.number;
    if (op == "!=") return a.number != b.number;
    if (op == "<") return a.number < b.number;
    if (op == "<=") return a.number <= b.number;
    if (op == ">") return a.number > b.number;
    return a.number >= b.number;
  }
  if (a.kind == XacroValue::Kind::string && b.kind == XacroValue::Kind::string) {
    const int c = a.text.compare(b.text);
    if (op == "==") return c == 0;
    if (op == "!=") return c != 0;
    if (op == "<") return c < 0;
    if (op == "<=") return c <= 0;
    if (op == ">") return c > 0;
    return c >= 0;
  }
  if (op == "==") return false;  // a string never equals a number, as in Python
  if (op == "!=") return true;
  throw XacroExpressionError("cannot order " + kind_name(a) + " and " + kind_name(b));
}

XacroValue call_function(const std::string& name, const std::vector<XacroValue>& args) {
  using Unary = double (*)(double);
  static const std::map<std::string, Unary> unary = {
      {"sin", [](double x) { return std::sin(x); }},
      {"cos", [](double x) { return std::cos(x); }},
      {"tan", [](double x) { return std::tan(x); }},
      {"asin", [](double x) { return std::asin(x); }},
      {"acos", [](double x) { return std::acos(x); }},
      {"atan", [](double x) { return std::atan(x); }},
      {"sqrt", [](double x) { return std::sqrt(x); }},
      {"exp", [](double x) { return std::exp(x); }},
      {"log", [](double x) { return std::log(x); }},
      {"fabs", [](double x) { return std::fabs(x); }},
      {"radians", [](double x) { return x * std::numbers::pi / 180.0; }},
      {"degrees", [](double x) { return x * 180.0 / std::numbers::pi; }},
      {"float", [](double x) { return x; }}};
  auto expect_args = [&](std::size_t n) {
    if (args.size() != n)
      throw XacroExpressionError(name + "() takes " + std::to_string(n) + " argument" +
                                 (n == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
  };
  if (const auto f = unary.find(name); f != unary.end()) {
    expect_args(1);
    const double x = number_of(args[0], name + "()");
    if ((name == "sqrt" || name == "log") && x < 0)
      throw XacroExpressionError(name + "() of a negative number");
    if ((name == "asin" || name == "acos") && std::abs(x) > 1)
      throw XacroExpressionError(name + "() of a number outside [-1, 1]");
    return XacroValue::real(f->second(x));
  }
  if (name == "atan2" || name == "pow") {
    expect_args(2);
    const double y = number_of(args[0], name + "()"), x = number_of(args[1], name + "()");
    return XacroValue::real(name == "atan2" ? std::atan2(y, x) : std::pow(y, x));
  }
  if (name == "abs") {
    expect_args(1);
    const double x = number_of(args[0], "abs()");
    return is_integral(args[0]) ? XacroValue::integer(std::abs(x)) : XacroValue::real(std::abs(x));
  }
  if (name == "floor" || name == "ceil" || name == "int") {
    expect_args(1);
    const double x = number_of(args[0], name + "()");
    return XacroValue::integer(name == "floor"  ? std::floor(x)
                               : name == "ceil" ? std::ceil(x)
                                                : std::trunc(x));
  }
  if (name == "min" || name == "max") {
    if (args.empty()) throw XacroExpressionError(name + "() needs at least one argument");
    XacroValue best = args[0];
    for (const auto& a : args)
      if (compare(name == "min" ? "<" : ">", a, best)) best = a;
    return best;
  }
  if (name == "str") {
    expect_args(1);
    return XacroValue::string(xacro_text(args[0]));
  }
  throw XacroExpressionError("unknown function '" + name + "'");
}

// Recursive descent over Python's precedence, lowest first.
class Parser {
 public:
  Parser(std::vector<Token> tokens, const XacroLookup& lookup)
      : tokens_(std::move(tokens)), lookup_(lookup) {}

  XacroValue parse() {
    XacroValue v = ternary();
    if (peek().kind != Token::Kind::end)
      throw XacroExpressionError("unexpected '" + peek().text + "'");
    return v;
  }

 private:
  const Token& peek() const { return tokens_[pos_]; }
  bool next_is(const std::string& text) const {
    return (peek().kind == Token::Kind::op || peek().kind == Token::Kind::name) &&
           peek().text == text;
  }
  bool accept(const std::string& text) {
    if (!next_is(text)) return false;
    ++pos_;
    return true;
  }
  void expect(const std::string& text) {
    if (!accept(text))
      throw XacroExpressionError(
          "expected '" + text + "'" +
          (peek().kind == Token::Kind::end ? " at the end" : ", got '" + peek().text + "'"));
  }

  struct Nested {
    explicit Nested(int& depth) : depth_(depth) {
      if (++depth_ > max_nesting)
        throw XacroExpressionError("expression nested deeper than " + std::to_string(max_nesting));
    }
    ~Nested() { --depth_; }
    int& depth_;
  };

  XacroValue ternary() {
    const Nested nested(depth_);
    XacroValue value = or_expr();
    if (!accept("if")) return value;
    const XacroValue condition = or_expr();
    expect("else");
    XacroValue otherwise = ternary();
    return xacro_truth(condition) ? value : otherwise;
  }
  XacroValue or_expr() {
    XacroValue v = and_expr();
    while (accept("or")) {
      XacroValue rhs = and_expr();
      if (!xacro_truth(v)) v = rhs;
    }
    return v;
  }
  XacroValue and_expr() {
    XacroValue v = not_expr();
    while (accept("and")) {
      XacroValue rhs = not_expr();
      if (xacro_truth(v)) v = rhs;
    }
    return v;
  }
  XacroValue not_expr() {
    if (accept("not")) {
      const Nested nested(depth_);
      return XacroValue::boolean(!xacro_truth(not_expr()));
    }
    return comparison();
  }
  XacroValue comparison() {
    XacroValue left = sum();
    bool all = true, chained = false;
    for (;;) {
      std::string op;
      for (const char* candidate : {"==", "!=", "<=", ">=", "<", ">"})
        if (next_is(candidate)) op = candidate;
      if (op.empty()) break;
      ++pos_;
      XacroValue right = sum();
      all = all && compare(op, left, right);
      left = right;
      chained = true;
    }
    return chained ? XacroValue::boolean(all) : left;
  }
  XacroValue sum() {
    XacroValue v = product();
    for (;;) {
      if (accept("+")) v = arithmetic("+", v, product());
      else if (accept("-")) v = arithmetic("-", v, product());
      else return v;
    }
  }
  XacroValue product() {
    XacroValue v = unary();
    for (;;) {
      std::string op;
      for (const char* candidate : {"*", "//", "/", "%"})
        if (next_is(candidate)) op = candidate;
      if (op.empty()) return v;
      ++pos_;
      v = arithmetic(op, v, unary());
    }
  }
  XacroValue unary() {
    if (next_is("-") || next_is("+")) {
      const bool minus = peek().text == "-";
      ++pos_;
      const Nested nested(depth_);
      XacroValue v = unary();
      number_of(v, minus ? "-" : "+");
      if (v.kind == XacroValue::Kind::boolean) v.kind = XacroValue::Kind::integer;
      if (minus) v.number = -v.number;
      return v;
    }
    return power();
  }
  XacroValue power() {
    XacroValue base = primary();
    if (!accept("**")) return base;
    const Nested nested(depth_);
    return arithmetic("**", base, unary());  // right-associative, binds tighter than unary left
  }
  XacroValue primary() {
    const Token token = peek();
    if (token.kind == Token::Kind::end) throw XacroExpressionError("expression ends early");
    ++pos_;
    if (token.kind == Token::Kind::number) return number(token.text);
    if (token.kind == Token::Kind::string) return XacroValue::string(token.text);
    if (token.kind == Token::Kind::op) {
      if (token.text != "(") throw XacroExpressionError("unexpected '" + token.text + "'");
      XacroValue v = ternary();
      expect(")");
      return v;
    }
    std::string name = token.text;
    if (name == "math" && accept(".")) {  // math.pi, math.cos(...): the same names
      if (peek().kind != Token::Kind::name)
        throw XacroExpressionError("expected a name after 'math.'");
      name = peek().text;
      ++pos_;
    }
    if (accept("(")) {
      std::vector<XacroValue> args;
      if (!accept(")")) {
        do args.push_back(ternary());
        while (accept(","));
        expect(")");
      }
      return call_function(name, args);
    }
    if (next_is("."))
      throw XacroExpressionError("attribute access '" + name + ".' is not supported");
    if (auto v = lookup_(name)) return *v;
    if (name == "pi") return XacroValue::real(std::numbers::pi);
    if (name == "e") return XacroValue::real(std::numbers::e);
    if (name == "True" || name == "true") return XacroValue::boolean(true);
    if (name == "False" || name == "false") return XacroValue::boolean(false);
    throw XacroExpressionError("undefined property '" + name + "'");
  }
  static XacroValue number(const std::string& text) {
    const bool real = text.find_first_of(".eE") != std::string::npos;
    double v = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (error != std::errc() || end != text.data() + text.size())
      throw XacroExpressionError("bad number '" + text + "'");
    return real ? XacroValue::real(v) : XacroValue::integer(v);
  }

  std::vector<Token> tokens_;
  const XacroLookup& lookup_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

XacroValue evaluate_xacro_expression(std::string_view expression, const XacroLookup& lookup) {
  return Parser(tokenize(expression), lookup).parse();
}

XacroValue xacro_literal(const std::string& text) {
  if (text.size() >= 2 && text.front() == '\'' && text.back() == '\'')
    return XacroValue::string(text.substr(1, text.size() - 2));
  if (text.find('_') != std::string::npos) return XacroValue::string(text);
  if (text == "true" || text == "True") return XacroValue::boolean(true);
  if (text == "false" || text == "False") return XacroValue::boolean(false);
  // Python's int() and float() accept surrounding blanks and a leading '+'.
  std::size_t b = text.find_first_not_of(" \t\n\r");
  std::size_t e = text.find_last_not_of(" \t\n\r");
  if (b == std::string::npos) return XacroValue::string(text);
  std::string_view s(text.data() + b, e - b + 1);
  if (s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return XacroValue::string(text);
  const bool integer = s.find_first_not_of("-0123456789") == std::string_view::npos;
  const bool numeric = s.find_first_not_of("-+0123456789.eE") == std::string_view::npos ||
                       s == "inf" || s == "-inf" || s == "nan";
  if (!numeric) return XacroValue::string(text);
  double v = 0;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (error != std::errc() || end != s.data() + s.size()) return XacroValue::string(text);
  return integer ? XacroValue::integer(v) : XacroValue::real(v);
}

std::string xacro_text(const XacroValue& value) {
  switch (value.kind) {
    case XacroValue::Kind::string: return value.text;
    case XacroValue::Kind::boolean: return value.number != 0 ? "True" : "False";
    case XacroValue::Kind::integer: {
      char buffer[32];
      const auto r =
          std::to_chars(buffer, buffer + sizeof buffer, value.number, std::chars_format::fixed, 0);
      return std::string(buffer, r.ptr);
    }
    case XacroValue::Kind::real: break;
  }
  const double v = value.number;
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  // Python's repr: the shortest digits that round-trip, fixed for exponents in [-4, 16).
  char buffer[64];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::scientific);
  const std::string sci(buffer, r.ptr);
  const std::size_t e_at = sci.find('e');
  const int exponent = std::stoi(sci.substr(e_at + 1));
  std::string digits;
  for (char c : sci.substr(0, e_at))
    if (std::isdigit(static_cast<unsigned char>(c))) digits += c;
  const std::string sign = v < 0 ? "-" : "";
  if (exponent < -4 || exponent >= 16) {
    std::string mantissa = digits.substr(0, 1);
    if (digits.size() > 1) mantissa += "." + digits.substr(1);
    const std::string magnitude = std::to_string(std::abs(exponent));
    return sign + mantissa + "e" + (exponent < 0 ? "-" : "+") + (magnitude.size() < 2 ? "0" : "") +
           magnitude;
  }
  std::string out;
  if (exponent < 0) {
    out = "0." + std::string(static_cast<std::size_t>(-exponent - 1), '0') + digits;
  } else {
    const auto point = static_cast<std::size_t>(exponent) + 1;
    if (digits.size() <= point) out = digits + std::string(point - digits.size(), '0') + ".0";
    else out = digits.substr(0, point) + "." + digits.substr(point);
  }
  return sign + out;
}

bool xacro_truth(const XacroValue& value) {
  return value.kind == XacroValue::Kind::string ? !value.text.empty() : value.number != 0;
}

}  // namespace shapectl
