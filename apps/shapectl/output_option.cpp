#include "output_option.hpp"

#include <shapectl/io/atomic_file.hpp>
#include <shapectl/io/input_error.hpp>

namespace shapectl::cli {

CLI::Validator writable_output() {
  return CLI::Validator(
      [](std::string& file) -> std::string {
        try {
          check_writable(file);
        } catch (const InputError& e) {
          return e.what();
        }
        return "";
      },
      "", "writable output");
}

}  // namespace shapectl::cli
