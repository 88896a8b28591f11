#include <shapectl/link/stop_signal.hpp>

#include <csignal>
#include <cstdlib>

namespace shapectl {

namespace {

volatile std::sig_atomic_t signals_received = 0;

extern "C" void on_stop_signal(int) {
  if (signals_received) std::_Exit(130);
  signals_received = 1;
}

}  // namespace

void install_stop_signal_handlers() {
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
}

bool stop_signal_received() { return signals_received > 0; }

}  // namespace shapectl
