#include <shapectl/io/ascii_case.hpp>

namespace shapectl {

std::string ascii_lowercase(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::string lowercase_extension(const std::filesystem::path& file) {
  return ascii_lowercase(file.extension().string());
}

}  // namespace shapectl
