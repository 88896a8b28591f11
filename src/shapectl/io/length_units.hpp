#pragma once
// "units" in an input file (a mesh's, a targets file's): the factor from the file's
// coordinates to metres.
#include <optional>
#include <string_view>

namespace shapectl {

// 1 for "m", 1e-2 for "cm", 1e-3 for "mm"; none for anything else.
inline std::optional<double> metres_per_unit(std::string_view units) {
  if (units == "m") return 1;
  if (units == "cm") return 1e-2;
  if (units == "mm") return 1e-3;
  return std::nullopt;
}

}  // namespace shapectl
