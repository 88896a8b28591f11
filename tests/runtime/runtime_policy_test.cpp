// The runtime policy: each setting shows in the library it sets (TBB, OpenBLAS, glibc's heap),
// applying the same settings twice changes nothing, and the environment's variables win.
#include <malloc.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <gtest/gtest.h>

#include <shapectl/io/input_error.hpp>
#include <shapectl/runtime/blas_threads.hpp>
#include <shapectl/runtime/runtime_policy.hpp>
#include <shapectl/runtime/worker_threads.hpp>

extern "C" void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k,
                       const double* alpha, const double* a, const int* lda, const double* b,
                       const int* ldb, const double* beta, double* c, const int* ldc);

namespace shapectl::runtime {
namespace {

// The process's threads (their ids in /proc/self/task).
std::set<std::string> thread_ids() {
  std::set<std::string> ids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task"))
    ids.insert(entry.path().filename().string());
  return ids;
}

bool lost_one_of(const std::set<std::string>& before, const std::set<std::string>& after) {
  for (const auto& id : before)
    if (!after.count(id)) return true;
  return false;
}

// A product large enough that OpenBLAS splits it over its pool threads.
void multiply() {
  const int n = 256;
  const std::vector<double> a(n * n, 1.0), b(n * n, 1.0);
  std::vector<double> c(n * n, 0.0);
  const double one = 1, zero = 0;
  dgemm_("N", "N", &n, &n, &n, &one, a.data(), &n, b.data(), &n, &zero, c.data(), &n);
  ASSERT_EQ(c[0], n);
}

// Settings that touch only OpenBLAS's threads.
RuntimeSettings blas_only(int idle_timeout) {
  return {.blas_threads = 2,
          .blas_idle_timeout = idle_timeout,
          .keep_freed_heap = false,
          .start_threads = false};
}

TEST(RuntimePolicy, IdleBlasThreadsGetTheTimeoutWithoutARestartOfTheProgram) {
  ASSERT_GE(std::thread::hardware_concurrency(), 2u) << "needs OpenBLAS's pool: 2 cores";
  apply_runtime_policy(blas_only(28));  // OpenBLAS's default, its pool running
  multiply();
  const auto before = thread_ids();

  apply_runtime_policy(blas_only(4));
  EXPECT_EQ(current_blas_idle_timeout(), 4);
  // The pool started with the old timeout is gone; the next threaded call starts a new one.
  const auto after = thread_ids();
  EXPECT_TRUE(lost_one_of(before, after));
  multiply();
  EXPECT_TRUE(lost_one_of(thread_ids(), after)) << "no new pool thread";
}

TEST(RuntimePolicy, ApplyingTheSameSettingsTwiceChangesNothing) {
  const RuntimeSettings settings{.threads = 1};
  apply_runtime_policy(settings);
  multiply();
  const auto threads = thread_ids();
  apply_runtime_policy(settings);
  EXPECT_EQ(thread_ids(), threads) << "OpenBLAS's pool restarted, or new threads";
  EXPECT_EQ(applied_runtime_settings(), settings);
  EXPECT_EQ(current_blas_idle_timeout(), 4);
  EXPECT_EQ(worker_thread_limit(), 1);
}

TEST(RuntimePolicy, TheWorkerThreadCountLimitsTbbsLoops) {
  apply_runtime_policy({.threads = 1});
  EXPECT_EQ(worker_thread_limit(), 1);
  std::mutex mutex;
  std::set<std::thread::id> seen;
  tbb::parallel_for(0, 10000, [&](int) {
    const std::lock_guard lock(mutex);
    seen.insert(std::this_thread::get_id());
  });
  EXPECT_EQ(seen.size(), 1u);
  apply_runtime_policy({.threads = 0});
  EXPECT_EQ(worker_thread_limit(), tbb::info::default_concurrency());
}

TEST(RuntimePolicy, BlasThreadsAreChosenPerFactorizationUnlessFixed) {
  apply_runtime_policy({.blas_threads = 1, .start_threads = false});
  use_blas_threads(true);
  EXPECT_EQ(current_blas_threads(), 1) << "a fixed count wins";
  apply_runtime_policy({.blas_threads = 0, .start_threads = false});
  use_blas_threads(true);
  EXPECT_EQ(current_blas_threads(), static_cast<int>(std::thread::hardware_concurrency()));
  use_blas_threads(false);
  EXPECT_EQ(current_blas_threads(), 1);
}

// A block between glibc's largest dynamic mmap threshold (32 MiB) and the policy's 64 MiB.
TEST(RuntimePolicy, LargeBlocksComeFromTheHeapAndStayAfterFree) {
  unsetenv("MALLOC_MMAP_THRESHOLD_");
  unsetenv("MALLOC_TRIM_THRESHOLD_");
  apply_runtime_policy({.keep_freed_heap = true, .start_threads = false});
  const std::size_t size = 48 << 20;
  const auto mapped_before = mallinfo2().hblkhd;
  auto* block = static_cast<volatile char*>(std::malloc(size));
  ASSERT_NE(block, nullptr);
  block[size - 1] = 1;
  EXPECT_LT(mallinfo2().hblkhd, mapped_before + size) << "the block was mapped on its own";
  std::free(const_cast<char*>(block));
  EXPECT_GE(mallinfo2().fordblks, size) << "the freed block went back to the system";
}

TEST(RuntimePolicy, TheEnvironmentsVariablesWin) {
  setenv("SHAPECTL_THREADS", "3", 1);
  setenv("OPENBLAS_THREAD_TIMEOUT", "10", 1);
  const RuntimeSettings settings = settings_from_environment();
  EXPECT_EQ(settings.threads, 3);
  EXPECT_EQ(settings.blas_idle_timeout, current_blas_idle_timeout()) << "as OpenBLAS read it";
  setenv("SHAPECTL_THREADS", "two", 1);
  try {
    settings_from_environment();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "SHAPECTL_THREADS: expected a whole number >= 0 (0: one per core), got 'two'");
  }
  unsetenv("SHAPECTL_THREADS");
  unsetenv("OPENBLAS_THREAD_TIMEOUT");
  EXPECT_EQ(settings_from_environment(), RuntimeSettings{});
}

// TBB's workers exist once the policy returns: counted in a fresh process (a death test's
// child re-runs this binary), where nothing has started them yet.
TEST(RuntimePolicy, StartThreadsStartsTbbsWorkersNow) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto started = [](bool start) {
    const std::size_t before = thread_ids().size();
    apply_runtime_policy(
        {.blas_idle_timeout = 0, .keep_freed_heap = false, .start_threads = start});
    std::exit(thread_ids().size() > before ? 0 : 1);
  };
  EXPECT_EXIT(started(true), testing::ExitedWithCode(0), "");
  EXPECT_EXIT(started(false), testing::ExitedWithCode(1), "");
}

}  // namespace
}  // namespace shapectl::runtime
