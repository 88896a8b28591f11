#include <shapectl/linalg/serial_openmp.hpp>

#include <gtest/gtest.h>

#include <thread>

// The OpenMP runtime CHOLMOD brings into every shapectl binary.
extern "C" int omp_get_max_active_levels() __attribute__((weak));

namespace shapectl {
namespace {

TEST(SerialOpenMp, GuardsMakeThisThreadsRegionsSerialAndRestoreItsSettingWhenTheLastEnds) {
  ASSERT_NE(omp_get_max_active_levels, nullptr) << "no OpenMP runtime loaded: nothing to test";
  const int before = omp_get_max_active_levels();
  ASSERT_GT(before, 0);
  {
    SerialOpenMp outer;
    EXPECT_EQ(omp_get_max_active_levels(), 0);
    {
      SerialOpenMp inner;
      EXPECT_EQ(omp_get_max_active_levels(), 0);
    }
    EXPECT_EQ(omp_get_max_active_levels(), 0) << "the inner guard restored too early";
  }
  EXPECT_EQ(omp_get_max_active_levels(), before);
}

TEST(SerialOpenMp, AnotherThreadsGuardLeavesThisThreadAlone) {
  ASSERT_NE(omp_get_max_active_levels, nullptr) << "no OpenMP runtime loaded: nothing to test";
  SerialOpenMp mine;
  int seen_inside_other = -1;
  std::thread other([&] {
    SerialOpenMp theirs;
    seen_inside_other = omp_get_max_active_levels();
  });
  other.join();
  EXPECT_EQ(seen_inside_other, 0);
  EXPECT_EQ(omp_get_max_active_levels(), 0) << "the other thread's guard ended this one's";
}

}  // namespace
}  // namespace shapectl
