#include <shapectl/runtime/blas_threads.hpp>

#include <atomic>
#include <cstdlib>
#include <string>

// OpenBLAS's thread control and, for the idle timeout, three functions its shared library
// exports (0.3.21: `nm -D`): the environment reader, the value it read, the pool's shutdown.
extern "C" void openblas_set_num_threads(int threads) __attribute__((weak));
extern "C" int openblas_get_num_threads() __attribute__((weak));
extern "C" int openblas_get_num_procs() __attribute__((weak));
extern "C" void openblas_read_env() __attribute__((weak));
extern "C" int openblas_thread_timeout() __attribute__((weak));
extern "C" int blas_thread_shutdown_() __attribute__((weak));

namespace shapectl::runtime {

namespace {
bool have_openblas() {
  return openblas_set_num_threads && openblas_get_num_threads && openblas_get_num_procs;
}
// set_blas_threads' count. OPENBLAS_NUM_THREADS, if set, fixes OpenBLAS's count from the start,
// in every process, whether it applied the runtime policy or not.
std::atomic<int>& fixed_threads() {
  static std::atomic<int> fixed{std::getenv("OPENBLAS_NUM_THREADS") ? current_blas_threads() : 0};
  return fixed;
}
std::atomic<int> chosen_threads{0};  // use_blas_threads' last choice; 0: none yet
}  // namespace

void use_blas_threads(bool many) {
  if (fixed_threads().load() > 0 || !have_openblas()) return;
  const int threads = many ? openblas_get_num_procs() : 1;
  if (chosen_threads.exchange(threads) != threads) openblas_set_num_threads(threads);
}

void set_blas_threads(int threads) {
  fixed_threads() = threads;
  chosen_threads = 0;  // the next use_blas_threads sets its choice again
  if (threads > 0 && have_openblas() && openblas_get_num_threads() != threads)
    openblas_set_num_threads(threads);
}

int current_blas_threads() { return have_openblas() ? openblas_get_num_threads() : 1; }

void set_blas_idle_timeout(int log2_cycles) {
  if (!openblas_read_env || !openblas_thread_timeout || !blas_thread_shutdown_) return;
  if (openblas_thread_timeout() == log2_cycles) return;
  if (setenv("OPENBLAS_THREAD_TIMEOUT", std::to_string(log2_cycles).c_str(), 1) != 0) return;
  openblas_read_env();
  blas_thread_shutdown_();
}

int current_blas_idle_timeout() { return openblas_thread_timeout ? openblas_thread_timeout() : 0; }

}  // namespace shapectl::runtime
