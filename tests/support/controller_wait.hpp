#pragma once
// Waiting for the controller's thread in tests, bounded: a broken controller fails the test
// instead of hanging it.
#include <chrono>
#include <memory>

#include <shapectl/control/controller.hpp>

#include "support/wait_bound.hpp"

namespace shapectl::test {

// Waits until `done(snapshot)` holds for a published snapshot, at most wait_bound(seconds); returns
// the last snapshot seen (check `done` on it again).
template <class Done>
std::shared_ptr<const ControllerSnapshot> wait_until(const Controller& c, Done done,
                                                     double seconds) {
  auto s = c.snapshot();
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_bound(seconds));
  while (!done(*s) && std::chrono::steady_clock::now() < deadline)
    s = c.wait_for_snapshot(s->sequence, 0.1);
  return s;
}

}  // namespace shapectl::test
