#pragma once
// A session log: one JSON object per line (JSON Lines), each with "t" (seconds since the log
// was opened) and "event" (what happened), written and flushed as it happens so a crash loses
// at most the line being written. Any thread may write. A log has a size cap: a line that would
// take the file past it first moves the file to FILE.1 (FILE.1 to FILE.2, ..., the oldest of
// `keep` dropped) and starts FILE again with the header events (write_header), so every
// file, the current one included, can be read on its own.
//
//   {"t":0.000,"event":"session","scene":"bar.json", ...}
//   {"t":0.012,"event":"command","channel":"left","joints":[...], ...}
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace shapectl {

struct SessionLogLimits {
  // Bytes per file: each file stays within it (unless its header and one line alone are larger).
  std::uint64_t max_bytes = 100u << 20;
  int keep = 3;  // rotated files kept (FILE.1 newest ... FILE.keep oldest); 0: none
};

class SessionLog {
 public:
  // Creates or truncates `file`; InputError "<file>: cannot open for writing" when impossible.
  explicit SessionLog(const std::filesystem::path& file, SessionLogLimits limits = {});
  ~SessionLog();
  SessionLog(const SessionLog&) = delete;
  SessionLog& operator=(const SessionLog&) = delete;

  // Appends {"t": elapsed(), "event": event, ...fields}; `fields` must be an object or null.
  void write(std::string_view event, const nlohmann::json& fields = nullptr);
  // Like write, and repeated at the top of every file after a rotation (the last one written
  // of each header event): what a reader needs before the events that follow.
  void write_header(std::string_view event, const nlohmann::json& fields = nullptr);
  double elapsed() const;  // seconds since opened
  const std::filesystem::path& file() const { return file_; }
  // FILE.k, the k-th newest rotated file (k >= 1).
  std::filesystem::path rotated_file(int k) const;

 private:
  std::string line(std::string_view event, const nlohmann::json& fields) const;
  void append(std::string_view event, const std::string& text, bool header);
  void rotate();  // with mutex_ held

  std::filesystem::path file_;
  SessionLogLimits limits_;
  std::FILE* out_ = nullptr;        // null if a rotation could not reopen the file
  std::uint64_t bytes_ = 0;         // in the current file
  std::uint64_t header_bytes_ = 0;  // of those, the header repeated at its top
  std::vector<std::pair<std::string, std::string>> headers_;  // event, line
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

// Reads a log. A line that is not a JSON object with a number "t" (0 to 1e9 s) and a string
// "event" is an InputError "<file>:<line>: ..."; except an unterminated last line (a crash
// mid-write), which is skipped and counted in `*truncated_lines` if given.
std::vector<LoggedEvent> read_session_log(const std::filesystem::path& file,
                                          int* truncated_lines = nullptr);

}  // namespace shapectl
