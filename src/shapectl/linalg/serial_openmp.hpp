#pragma once
// Runs the OpenMP parallel regions opened on this thread, while a guard lives, on one thread.
//
// Why: Debian's CHOLMOD (SuiteSparse 5.12) opens its supernodal regions with a fixed
// num_threads(4), whatever the machine. On 2 cores, beside our own threads, that
// oversubscribes them and every supernode waits on spinning threads: a 12.8k-tet TetGen bar
// factored in 75 ms with them and 18 ms without (docs/benchmarks.md, "CHOLMOD's OpenMP
// threads"). shapectl itself uses no OpenMP; it parallelises with TBB and its own threads.
//
// The setting (max-active-levels) is per thread in libgomp, so each thread's guards save and
// restore that thread's value; guards nest. Without an OpenMP runtime in the process it does
// nothing.
namespace shapectl {

class SerialOpenMp {
 public:
  SerialOpenMp();
  ~SerialOpenMp();
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;
};

}  // namespace shapectl
