#include <shapectl/linalg/serial_openmp.hpp>

// The OpenMP runtime's, if one is loaded (weak: absent otherwise). Zero active levels makes
// every parallel region run on the thread that opens it.
extern "C" int omp_get_max_active_levels() __attribute__((weak));
extern "C" void omp_set_max_active_levels(int levels) __attribute__((weak));

namespace shapectl {

namespace {
thread_local int serial_guards = 0;         // live guards on this thread
thread_local int levels_before_guards = 0;  // this thread's setting before the outermost one
bool have_openmp_runtime() { return omp_get_max_active_levels && omp_set_max_active_levels; }
}  // namespace

SerialOpenMp::SerialOpenMp() {
  if (!have_openmp_runtime() || serial_guards++ > 0) return;
  levels_before_guards = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
}

SerialOpenMp::~SerialOpenMp() {
  if (!have_openmp_runtime() || --serial_guards > 0) return;
  omp_set_max_active_levels(levels_before_guards);
}

}  // namespace shapectl
