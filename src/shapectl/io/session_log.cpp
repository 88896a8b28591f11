#include <shapectl/io/session_log.hpp>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/io/json_input.hpp>

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
  const std::string text =
      line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::lock_guard lock(mutex_);
  // One write and a flush per line: the OS has every finished line even if we crash next.
  std::fwrite(text.data(), 1, text.size(), out_);
  std::fflush(out_);
}

std::vector<LoggedEvent> read_session_log(const std::filesystem::path& file, int* truncated_lines) {
  // An hour at 250 Hz on two arms is ~400 MB; a FIFO or anything larger is refused, not read.
  const std::string content = read_input_file(file, max_session_log_bytes, "session log");
  std::vector<LoggedEvent> events;
  if (truncated_lines) *truncated_lines = 0;
  int line = 0;
  for (std::size_t begin = 0; begin < content.size();) {
    const std::size_t newline = content.find('\n', begin);
    const bool last_unterminated = newline == std::string::npos;
    const std::size_t end = last_unterminated ? content.size() : newline;
    const std::string_view text(content.data() + begin, end - begin);
    begin = end + 1;
    ++line;
    if (text.empty()) continue;
    const std::string where = file.string() + ":" + std::to_string(line);
    nlohmann::json j;
    try {
      j = parse_json_text(text, where, {.max_bytes = 1u << 20, .max_depth = 16});
    } catch (const InputError&) {
      j = nlohmann::json();  // reported below, or skipped when a crash cut the last line short
    }
    const bool valid = j.is_object() && j.contains("t") && j["t"].is_number() &&
                       j.contains("event") && j["event"].is_string();
    if (!valid) {
      if (last_unterminated) {  // the line a crash cut short
        if (truncated_lines) ++*truncated_lines;
        break;
      }
      throw InputError(where, "",
                       "expected a JSON object with a number \"t\" and a string "
                       "\"event\", got: " +
                           bounded_preview(text));
    }
    events.push_back({line, j["t"].get<double>(), j["event"].get<std::string>(), std::move(j)});
  }
  return events;
}

}  // namespace shapectl
