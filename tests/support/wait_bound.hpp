#pragma once
// The bound of a test's wait for another thread, in seconds. Such a bound only keeps a broken
// thread from hanging the test, it claims no speed: under ThreadSanitizer, which runs code
// 5-15x slower (cmake/tsan.cmake), it is 20 times longer.
namespace shapectl::test {

constexpr double wait_bound(double seconds) {
#if defined(__SANITIZE_THREAD__)
  return 20 * seconds;
#else
  return seconds;
#endif
}

}  // namespace shapectl::test
