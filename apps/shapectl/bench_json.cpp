#include "bench_json.hpp"

#include <chrono>
#include <ctime>

#include <shapectl/io/json_output.hpp>

namespace shapectl::cli {

void write_bench_record(const std::string& file, nlohmann::json record) {
  if (file.empty()) return;
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  record["date"] = date;
  write_json_file(file, record);
}

}  // namespace shapectl::cli
