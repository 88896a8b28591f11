#pragma once
// OpenBLAS's threads (Debian's pthreads build, 0.3.21, is the BLAS shapectl links). Each
// function does nothing when the process's BLAS is not OpenBLAS: its symbols are looked up weak.
namespace shapectl::runtime {

// Before each factorization and solve: `many` gives OpenBLAS one thread per core, else one.
// OpenBLAS threads pay off only for large dense blocks; on small ones they cost more in
// hand-offs and spinning than they save (`shapectl bench` on the YuMi bar: 10 % faster with
// one thread; a 50k-tet band factorization: 22 % slower). Nothing while a fixed count is set.
void use_blas_threads(bool many);

// n > 0: n threads for every BLAS call from now on; 0: use_blas_threads chooses again.
void set_blas_threads(int threads);

// OpenBLAS's thread count now (1 without OpenBLAS).
int current_blas_threads();

// OPENBLAS_THREAD_TIMEOUT without a restart of the program. OpenBLAS reads the variable when
// it loads and has no setter; this sets it, has OpenBLAS read its environment again and stops
// the pool's threads (as OpenBLAS itself does before every fork), so that the next threaded
// call starts them with the new timeout. Only while no other thread is inside a BLAS call:
// at start-up. Nothing when the pool already has this timeout.
void set_blas_idle_timeout(int log2_cycles);

// The timeout OpenBLAS starts pool threads with (0: its own default, 2^28 cycles).
int current_blas_idle_timeout();

}  // namespace shapectl::runtime
