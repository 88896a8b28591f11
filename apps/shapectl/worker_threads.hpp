#pragma once

namespace shapectl::cli {

// Starts TBB's worker threads now, before the command runs. Otherwise the first parallel loop
// pays for their start (~0.5 ms on 2 cores), inside the first solve and its time.
void start_worker_threads();

}  // namespace shapectl::cli
