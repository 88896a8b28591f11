#include <shapectl/io/json_output.hpp>

#include <algorithm>
#include <fstream>
#include <unistd.h>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

void write_text_file_atomically(const std::filesystem::path& file, const std::string& text) {
  const auto temporary = std::filesystem::path(file.string() + ".tmp" + std::to_string(getpid()));
  {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) throw InputError(file.string(), "", "cannot write file (does the directory exist?)");
    out << text;
    out.flush();
    if (!out) {
      std::filesystem::remove(temporary);
      throw InputError(file.string(), "", "writing failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw InputError(file.string(), "", "cannot replace file: " + ec.message());
  }
}

namespace {
// Indented like dump(1), but arrays of numbers stay on one line ([x, y, z]).
void pretty(const nlohmann::json& v, int depth, std::string& out) {
  const std::string pad(depth, ' ');
  const bool flat_array = v.is_array() && std::all_of(v.begin(), v.end(), [](const auto& e) {
                            return e.is_primitive();
                          });
  if (v.is_object() && !v.empty()) {
    out += "{\n";
    std::size_t k = 0;
    for (auto it = v.begin(); it != v.end(); ++it, ++k) {
      out += pad + " " + nlohmann::json(it.key()).dump() + ": ";
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
    out += v.dump();
  }
}
}  // namespace

std::string to_pretty_json(const nlohmann::json& value) {
  std::string out;
  pretty(value, 0, out);
  return out + "\n";
}

void write_json_file(const std::filesystem::path& file, const nlohmann::json& value) {
  write_text_file_atomically(file, to_pretty_json(value));
}

nlohmann::json positions_to_json(const Positions& x) {
  nlohmann::json out = nlohmann::json::array();
  for (int i = 0; i < x.size() / 3; ++i) out.push_back({x[3 * i], x[3 * i + 1], x[3 * i + 2]});
  return out;
}

}  // namespace shapectl
