#include <shapectl/io/session_log.hpp>

#include <fstream>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

SessionLog::SessionLog(const std::filesystem::path& file)
    : file_(file), start_(std::chrono::steady_clock::now()) {
  out_ = std::fopen(file.c_str(), "w");
  if (!out_) throw InputError(file.string(), "", "cannot open for writing");
}

SessionLog::~SessionLog() {
  if (out_) std::fclose(out_);
}

double SessionLog::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void SessionLog::write(std::string_view event, const nlohmann::json& fields) {
  nlohmann::json line = {{"t", elapsed()}, {"event", event}};
  if (fields.is_object()) line.update(fields);
  const std::string text = line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::lock_guard lock(mutex_);
  // One write and a flush per line: the OS has every finished line even if we crash next.
  std::fwrite(text.data(), 1, text.size(), out_);
  std::fflush(out_);
}

std::vector<LoggedEvent> read_session_log(const std::filesystem::path& file, int* truncated_lines) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open");
  std::vector<LoggedEvent> events;
  std::string text;
  int line = 0;
  if (truncated_lines) *truncated_lines = 0;
  while (std::getline(in, text)) {
    ++line;
    const bool last_unterminated = in.eof();
    if (text.empty()) continue;
    const std::string where = file.string() + ":" + std::to_string(line);
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    const bool valid = !j.is_discarded() && j.is_object() && j.contains("t") &&
                       j["t"].is_number() && j.contains("event") && j["event"].is_string();
    if (!valid) {
      if (last_unterminated) {  // the line a crash cut short
        if (truncated_lines) ++*truncated_lines;
        break;
      }
      throw InputError(where, "", "expected a JSON object with a number \"t\" and a string "
                                  "\"event\", got: " + text.substr(0, 80));
    }
    events.push_back({line, j["t"].get<double>(), j["event"].get<std::string>(), std::move(j)});
  }
  return events;
}

}  // namespace shapectl
