#pragma once
// Bad input from a file or the command line: says where, what was expected, what was found.
#include <sstream>
#include <stdexcept>
#include <string>

namespace shapectl {

class InputError : public std::runtime_error {
 public:
  // "scene.json: object.material.mu: expected a positive number, got -3"
  template <class Found>
  InputError(const std::string& source, const std::string& where, const std::string& expected,
             const Found& found)
      : std::runtime_error(
            compose(source, where, "expected " + expected + ", got " + show(found))) {}
  // "bar.msh:1042: element 511: node 9000 out of range (mesh has 1536 nodes)"
  InputError(const std::string& source, const std::string& where, const std::string& problem)
      : std::runtime_error(compose(source, where, problem)) {}
  explicit InputError(const std::string& message) : std::runtime_error(message) {}

 private:
  static std::string compose(const std::string& source, const std::string& where,
                             const std::string& problem) {
    std::string s = source;
    if (!where.empty()) s += (s.empty() ? "" : ": ") + where;
    return s + ": " + problem;
  }
  template <class Found>
  static std::string show(const Found& found) {
    std::ostringstream out;
    out << found;
    return out.str();
  }
};

}  // namespace shapectl
