// The ${...} evaluator: Python's precedence and typing, the math functions, and its errors.
#include <shapectl/robot/xacro_expression.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

namespace shapectl {
namespace {

const std::map<std::string, std::string> kProperties = {{"mass", "3.7000"},  {"count", "4"},
                                                        {"name", "'arm'"},   {"prefix", "left_"},
                                                        {"flag", "false"},   {"empty", "''"},
                                                        {"pi", "3.14159265"}};

XacroValue eval(const std::string& expression) {
  return evaluate_xacro_expression(expression, [](const std::string& name) {
    const auto it = kProperties.find(name);
    return it == kProperties.end() ? std::nullopt : std::optional(xacro_literal(it->second));
  });
}
double number(const std::string& expression) {
  const XacroValue v = eval(expression);
  EXPECT_TRUE(v.is_number()) << expression;
  return v.number;
}
std::string text(const std::string& expression) { return xacro_text(eval(expression)); }
std::string error_of(const std::string& expression) {
  try {
    eval(expression);
  } catch (const XacroExpressionError& e) {
    return e.what();
  }
  return "";
}
XacroValue no_properties(const std::string& expression) {
  return evaluate_xacro_expression(expression, [](const std::string&) { return std::nullopt; });
}

TEST(XacroExpression, FollowsPythonPrecedence) {
  EXPECT_EQ(number("1 + 2 * 3"), 7);
  EXPECT_EQ(number("(1 + 2) * 3"), 9);
  EXPECT_EQ(number("2 ** 3 ** 2"), 512);  // right-associative
  EXPECT_EQ(number("-2 ** 2"), -4);       // ** binds tighter than a unary minus on its left
  EXPECT_EQ(number("2 ** -1"), 0.5);
  EXPECT_EQ(number("10 - 4 - 3"), 3);      // left-associative
  EXPECT_EQ(number("7 // 2 + 7 % 3"), 4);  // 3 + 1
  EXPECT_EQ(number("-7 // 2"), -4);        // floor division, as Python
  EXPECT_EQ(number("-7 % 3"), 2);
  EXPECT_EQ(number("--3"), 3);
  EXPECT_DOUBLE_EQ(number("1 / 4"), 0.25);  // true division even for integers
}

TEST(XacroExpression, TypesValuesAsPythonPrintsThem) {
  EXPECT_EQ(text("3 * 2"), "6");
  EXPECT_EQ(text("3 / 1"), "3.0");
  EXPECT_EQ(text("mass"), "3.7");  // "3.7000" is a number
  EXPECT_EQ(text("count * 2"), "8");
  EXPECT_EQ(text("2.0 * pi"), "6.2831853");  // the description's own pi shadows math.pi
  EXPECT_EQ(text("1e-5"), "1e-05");
  EXPECT_EQ(text("0.0001"), "0.0001");
  EXPECT_EQ(text("1e16"), "1e+16");
  EXPECT_EQ(text("123456.5"), "123456.5");
  EXPECT_EQ(text("-0.5"), "-0.5");
  EXPECT_EQ(xacro_text(no_properties("pi / 2")), "1.5707963267948966");
  EXPECT_EQ(xacro_text(no_properties("radians(90)")), "1.5707963267948966");
  EXPECT_EQ(text("1 < 2"), "True");
  EXPECT_EQ(text("name"), "arm");  // quotes removed
  EXPECT_EQ(text("prefix + 'link'"), "left_link");
}

TEST(XacroExpression, ComparesAndCombinesBooleansLikePython) {
  EXPECT_EQ(text("not flag"), "True");
  EXPECT_EQ(text("not empty"), "True");  // '' is false
  EXPECT_EQ(text("name == 'arm'"), "True");
  EXPECT_EQ(text("name != 'arm'"), "False");
  EXPECT_EQ(text("count == '4'"), "False");   // a number never equals a string
  EXPECT_EQ(text("1 < count <= 4"), "True");  // chained comparison
  EXPECT_EQ(text("1 < count < 4"), "False");
  EXPECT_EQ(text("flag or count"), "4");  // `or` returns an operand
  EXPECT_EQ(text("count and name"), "arm");
  EXPECT_EQ(text("not 1 == 2"), "True");  // not binds looser than ==
  EXPECT_EQ(text("'yes' if count > 3 else 'no'"), "yes");
  EXPECT_EQ(text("'yes' if flag else 'no'"), "no");
}

TEST(XacroExpression, MathFunctions) {
  EXPECT_DOUBLE_EQ(number("sin(0.3)"), std::sin(0.3));
  EXPECT_DOUBLE_EQ(number("cos(0.3) + tan(0.3)"), std::cos(0.3) + std::tan(0.3));
  EXPECT_DOUBLE_EQ(number("asin(0.3) + acos(0.3) + atan(0.3)"),
                   std::asin(0.3) + std::acos(0.3) + std::atan(0.3));
  EXPECT_DOUBLE_EQ(number("atan2(1, -2)"), std::atan2(1.0, -2.0));
  EXPECT_DOUBLE_EQ(number("sqrt(2)"), std::sqrt(2.0));
  EXPECT_EQ(number("abs(-3)"), 3);
  EXPECT_EQ(text("floor(-2.5)"), "-3");
  EXPECT_EQ(text("ceil(2.1)"), "3");
  EXPECT_DOUBLE_EQ(number("math.cos(math.pi)"), -1.0);
  EXPECT_DOUBLE_EQ(number("degrees(radians(33))"), 33.0);
  EXPECT_EQ(number("max(1, count, 2)"), 4);
}

TEST(XacroExpression, ErrorsSayWhatWasExpected) {
  EXPECT_EQ(error_of("length * 2"), "undefined property 'length'");
  EXPECT_EQ(error_of("1 +"), "expression ends early");
  EXPECT_EQ(error_of("(1 + 2"), "expected ')' at the end");
  EXPECT_EQ(error_of("1 2"), "unexpected '2'");
  EXPECT_EQ(error_of("1 / 0"), "division by zero");
  EXPECT_EQ(error_of("name * 2"), "'*' expects numbers, got string 'arm'");
  EXPECT_EQ(error_of("sqrt(-1)"), "sqrt() of a negative number");
  EXPECT_EQ(error_of("atan2(1)"), "atan2() takes 2 arguments, got 1");
  EXPECT_EQ(error_of("frobnicate(1)"), "unknown function 'frobnicate'");
  EXPECT_EQ(error_of("'open"), "unterminated string literal");
  EXPECT_EQ(error_of("1 $ 2"), "unexpected character '$'");
  EXPECT_EQ(error_of("name < 1"), "cannot order string 'arm' and integer");
  EXPECT_EQ(error_of("d['key']"), "unexpected character '['");
  EXPECT_EQ(error_of(std::string(200, '(') + "1" + std::string(200, ')')),
            "expression nested deeper than 100");
}

TEST(XacroExpression, LiteralsAreTypedAsXacroTypesPropertyText) {
  EXPECT_EQ(xacro_literal("4").kind, XacroValue::Kind::integer);
  EXPECT_EQ(xacro_literal("4.0").kind, XacroValue::Kind::real);
  EXPECT_EQ(xacro_literal("-1e-3").number, -1e-3);
  EXPECT_EQ(xacro_literal("true").kind, XacroValue::Kind::boolean);
  EXPECT_EQ(xacro_literal("0 0 1").kind, XacroValue::Kind::string);
  EXPECT_EQ(xacro_literal("1_000").kind, XacroValue::Kind::string);  // '_' keeps text
  EXPECT_EQ(xacro_literal("'0.5'").text, "0.5");                     // quoted: a string
  EXPECT_EQ(xacro_literal("'0.5'").kind, XacroValue::Kind::string);
  EXPECT_EQ(xacro_literal("").kind, XacroValue::Kind::string);
}

}  // namespace
}  // namespace shapectl
