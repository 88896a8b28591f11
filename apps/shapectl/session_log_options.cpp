#include "session_log_options.hpp"

namespace shapectl::cli {

void add_session_log_options(CLI::App& cmd, SessionLogLimits& limits) {
  constexpr double mebibyte = 1 << 20;
  cmd.add_option_function<double>(
         "--log-max-mb",
         [&limits](double mb) { limits.max_bytes = static_cast<std::uint64_t>(mb * mebibyte); },
         "size cap of the session log in MiB: past it the file is rotated to LOG.1 "
         "(default 100)")
      ->check(CLI::Range(0.01, 1e6));
  cmd.add_option("--log-keep", limits.keep, "rotated session logs kept (LOG.1 ... LOG.N)")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
}

}  // namespace shapectl::cli
