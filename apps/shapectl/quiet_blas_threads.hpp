#pragma once

namespace shapectl::cli {

// OpenBLAS (the pthreads build Debian ships) reads OPENBLAS_THREAD_TIMEOUT once, when it loads,
// before main. By default an idle pool thread spins (sched_yield) for 2^28 cycles (~0.1 s) after
// every BLAS call, taking the second core from TBB's element kernels, a GUI and a robot link;
// with 2^4 it sleeps at once (`shapectl bench --sizes 1.5k,12k` on 2 cores: 5-15 % faster,
// docs/benchmarks.md). Unless the variable is set, this sets it and restarts the program
// (execv of /proc/self/exe, same arguments and pid); if that fails, the run goes on unchanged.
void restart_with_quiet_blas_threads(char** argv);

}  // namespace shapectl::cli
