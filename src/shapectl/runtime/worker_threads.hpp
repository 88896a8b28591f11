#pragma once

namespace shapectl::runtime {

// At most `threads` threads run TBB's parallel loops, process-wide; 0: one per core (TBB's
// default). Replaces the limit an earlier call set.
void limit_worker_threads(int threads);

// TBB's current limit: the threads its parallel loops may use.
int worker_thread_limit();

// Starts TBB's worker threads now, before the command runs. Otherwise the first parallel loop
// pays for their start (~0.5 ms on 2 cores), inside the first solve and its time.
void start_worker_threads();

}  // namespace shapectl::runtime
