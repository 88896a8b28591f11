#include <shapectl/io/session_log.hpp>

#include <algorithm>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/io/json_input.hpp>

namespace shapectl {

namespace {

constexpr double max_log_time = 1e9;  // s, 31 years

}  // namespace

SessionLog::SessionLog(const std::filesystem::path& file, SessionLogLimits limits)
    : file_(file), limits_(limits), start_(std::chrono::steady_clock::now()) {
  out_ = std::fopen(file.c_str(), "w");
  if (!out_) throw InputError(file.string(), "", "cannot open for writing");
}

SessionLog::~SessionLog() {
  if (out_) std::fclose(out_);
}

double SessionLog::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::filesystem::path SessionLog::rotated_file(int k) const {
  return file_.string() + "." + std::to_string(k);
}

std::string SessionLog::line(std::string_view event, const nlohmann::json& fields) const {
  nlohmann::json line = {{"t", elapsed()}, {"event", event}};
  if (fields.is_object()) line.update(fields);
  return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void SessionLog::write(std::string_view event, const nlohmann::json& fields) {
  append(event, line(event, fields), false);
}

void SessionLog::write_header(std::string_view event, const nlohmann::json& fields) {
  append(event, line(event, fields), true);
}

void SessionLog::append(std::string_view event, const std::string& text, bool header) {
  std::lock_guard lock(mutex_);
  if (header) {
    auto it = std::find_if(headers_.begin(), headers_.end(),
                           [&](const auto& h) { return h.first == event; });
    if (it == headers_.end()) it = headers_.insert(headers_.end(), {std::string(event), ""});
    it->second = text;
  }
  // A file holding only its header is not rotated again: a line larger than the cap still fits.
  if (bytes_ + text.size() > limits_.max_bytes && bytes_ > header_bytes_) {
    rotate();
    if (header) return;  // the new file starts with it
  }
  if (!out_) return;
  // One write and a flush per line: the OS has every finished line even if we crash next.
  std::fwrite(text.data(), 1, text.size(), out_);
  std::fflush(out_);
  // Header events at the top of the first file count as its header too.
  if (header && bytes_ == header_bytes_) header_bytes_ += text.size();
  bytes_ += text.size();
}

void SessionLog::rotate() {
  if (out_) std::fclose(out_);
  // Failures are ignored: the log must not stop the robot; the file is started again anyway, so
  // its size stays bounded.
  std::error_code ignored;
  for (int k = limits_.keep - 1; k >= 1; --k)
    std::filesystem::rename(rotated_file(k), rotated_file(k + 1), ignored);
  if (limits_.keep > 0) std::filesystem::rename(file_, rotated_file(1), ignored);
  out_ = std::fopen(file_.c_str(), "w");
  bytes_ = header_bytes_ = 0;
  if (!out_) return;
  for (const auto& [event, text] : headers_) {
    std::fwrite(text.data(), 1, text.size(), out_);
    header_bytes_ += text.size();
  }
  std::fflush(out_);
  bytes_ = header_bytes_;
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
    // "t" bounded: replay sleeps until it (a duration in nanoseconds must not overflow).
    const bool valid = j.is_object() && j.contains("t") && j["t"].is_number() &&
                       j["t"].get<double>() >= 0 && j["t"].get<double>() <= max_log_time &&
                       j.contains("event") && j["event"].is_string();
    if (!valid) {
      if (last_unterminated) {  // the line a crash cut short
        if (truncated_lines) ++*truncated_lines;
        break;
      }
      throw InputError(where, "",
                       "expected a JSON object with a number \"t\" from 0 to 1e9 (s) and "
                       "a string \"event\", got: " +
                           bounded_preview(text));
    }
    events.push_back({line, j["t"].get<double>(), j["event"].get<std::string>(), std::move(j)});
  }
  return events;
}

}  // namespace shapectl
