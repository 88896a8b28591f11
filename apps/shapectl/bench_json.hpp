#pragma once
// `shapectl bench --json FILE`: what the bench prints, also as JSON, for scripts/bench_table.py
// (the README's benchmark table). Each row adds its figures to the record as it prints them:
// {"scenes": {file: {row: {...}}}} or {"sizes": {"scene": file, "rows": [...], ...}}, times in
// seconds.
#include <string>

#include <nlohmann/json.hpp>

namespace shapectl::cli {

// Writes `record` to `file` with the time it was written (UTC); nothing when `file` is empty.
void write_bench_record(const std::string& file, nlohmann::json record);

}  // namespace shapectl::cli
