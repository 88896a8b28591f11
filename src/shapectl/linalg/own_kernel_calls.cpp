#include <shapectl/linalg/own_kernel_calls.hpp>

#include <atomic>

namespace shapectl {

namespace {
std::atomic<std::uint64_t> calls{0};
}  // namespace

std::uint64_t own_kernel_calls() { return calls.load(std::memory_order_relaxed); }
void count_own_kernel_call() { calls.fetch_add(1, std::memory_order_relaxed); }

}  // namespace shapectl
