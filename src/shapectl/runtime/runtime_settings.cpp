#include <shapectl/runtime/runtime_settings.hpp>

#include <charconv>
#include <cstdlib>
#include <string_view>

#include <shapectl/io/input_error.hpp>
#include <shapectl/runtime/blas_threads.hpp>

namespace shapectl::runtime {

namespace {
int whole_number_from(const char* variable) {
  const char* text = std::getenv(variable);
  if (!text) return 0;
  const std::string_view value(text);
  int n = -1;
  const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), n);
  if (error != std::errc() || end != value.data() + value.size() || n < 0)
    throw InputError(variable, "", "a whole number >= 0 (0: one per core)",
                     "'" + std::string(value) + "'");
  return n;
}
}  // namespace

RuntimeSettings settings_from_environment() {
  RuntimeSettings settings;
  settings.threads = whole_number_from("SHAPECTL_THREADS");
  if (std::getenv("OPENBLAS_NUM_THREADS")) settings.blas_threads = current_blas_threads();
  if (std::getenv("OPENBLAS_THREAD_TIMEOUT"))
    settings.blas_idle_timeout = current_blas_idle_timeout();
  return settings;
}

}  // namespace shapectl::runtime
