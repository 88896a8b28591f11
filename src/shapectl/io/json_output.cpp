#include <shapectl/io/json_output.hpp>

#include <algorithm>
#include <cmath>

#include <shapectl/io/atomic_file.hpp>

namespace shapectl {

namespace {

template <class Json>
std::string dumped(const Json& v) {
  return v.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// Our own results are a few levels deep: plain recursion is fine here.
template <class Json>
void pretty(const Json& v, int depth, std::string& out) {
  const std::string pad(depth, ' ');
  const bool flat_array = v.is_array() && std::all_of(v.begin(), v.end(), [](const auto& e) {
                            return e.is_primitive();
                          });
  if (v.is_object() && !v.empty()) {
    out += "{\n";
    std::size_t k = 0;
    for (auto it = v.begin(); it != v.end(); ++it, ++k) {
      out += pad + " " + dumped(Json(it.key())) + ": ";
      pretty(it.value(), depth + 1, out);
      out += k + 1 < v.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (v.is_array() && !v.empty() && !flat_array) {
    out += "[\n";
    for (std::size_t k = 0; k < v.size(); ++k) {
      out += pad + " ";
      pretty(v[k], depth + 1, out);
      out += k + 1 < v.size() ? ",\n" : "\n";
    }
    out += pad + "]";
  } else {
    out += dumped(v);
  }
}

template <class Json>
std::string pretty_text(const Json& value) {
  std::string out;
  pretty(value, 0, out);
  return out + "\n";
}

template <class Json>
std::optional<std::string> non_finite_in(const Json& v, const std::string& where) {
  if (v.is_number_float() && !std::isfinite(v.template get<double>())) return where;
  if (v.is_object())
    for (auto it = v.begin(); it != v.end(); ++it)
      if (auto found = non_finite_in(it.value(), where + (where.empty() ? "" : ".") + it.key()))
        return found;
  if (v.is_array())
    for (std::size_t k = 0; k < v.size(); ++k)
      if (auto found = non_finite_in(v[k], where + "[" + std::to_string(k) + "]")) return found;
  return std::nullopt;
}

}  // namespace

std::string to_pretty_json(const nlohmann::json& value) { return pretty_text(value); }
std::string to_pretty_json(const nlohmann::ordered_json& value) { return pretty_text(value); }

void write_json_file(const std::filesystem::path& file, const nlohmann::json& value) {
  write_file_atomically(file, pretty_text(value));
}
void write_json_file(const std::filesystem::path& file, const nlohmann::ordered_json& value) {
  write_file_atomically(file, pretty_text(value));
}

std::optional<std::string> first_non_finite(const nlohmann::json& value) {
  return non_finite_in(value, "");
}
std::optional<std::string> first_non_finite(const nlohmann::ordered_json& value) {
  return non_finite_in(value, "");
}

}  // namespace shapectl
