#include "worker_threads.hpp"

#include <tbb/parallel_for.h>

namespace shapectl::cli {

void start_worker_threads() {
  tbb::parallel_for(0, 2, [](int) {});
}

}  // namespace shapectl::cli
