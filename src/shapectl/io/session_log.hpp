#pragma once
// A session log: one JSON object per line (JSON Lines), each with "t" (seconds since the log
// was opened) and "event" (what happened), written and flushed as it happens so a crash loses
// at most the line being written. Any thread may write.
//
//   {"t":0.000,"event":"session","scene":"bar.json", ...}
//   {"t":0.012,"event":"command","channel":"left","joints":[...], ...}
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace shapectl {

class SessionLog {
 public:
  // Creates or truncates `file`; InputError "<file>: cannot open for writing" when impossible.
  explicit SessionLog(const std::filesystem::path& file);
  ~SessionLog();
  SessionLog(const SessionLog&) = delete;
  SessionLog& operator=(const SessionLog&) = delete;

  // Appends {"t": elapsed(), "event": event, ...fields}; `fields` must be an object or null.
  void write(std::string_view event, const nlohmann::json& fields = nullptr);
  double elapsed() const;  // seconds since opened
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  std::FILE* out_ = nullptr;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
};

// One line of a log read back, with its line number (1-based) for messages.
struct LoggedEvent {
  int line = 0;
  double t = 0;
  std::string event;
  nlohmann::json fields;  // the whole object, "t" and "event" included
};

// Reads a log. A line that is not a JSON object with a number "t" and a string "event" is an
// InputError "<file>:<line>: ..."; except an unterminated last line (a crash mid-write), which
// is skipped and counted in `*truncated_lines` if given.
std::vector<LoggedEvent> read_session_log(const std::filesystem::path& file,
                                          int* truncated_lines = nullptr);

}  // namespace shapectl
