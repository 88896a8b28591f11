#pragma once
// One table per enum of the names it has on the wire, on the command line and in files; the
// to_string/parse pair of each enum reads it (Ceres' types.h pattern, kept in one place).
#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace shapectl {

template <class E, std::size_t N>
struct EnumNames {
  std::array<std::pair<E, const char*>, N> entries;

  constexpr const char* name(E value) const {
    for (const auto& [v, n] : entries)
      if (v == value) return n;
    return "?";
  }
  bool parse(std::string_view text, E* value) const {
    for (const auto& [v, n] : entries)
      if (text == n) return *value = v, true;
    return false;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& entry : entries) out.push_back(entry.second);
    return out;
  }
};

template <class E, class... Entries>
constexpr auto enum_names(Entries... entries) {
  return EnumNames<E, sizeof...(Entries)>{{{entries...}}};
}

}  // namespace shapectl
