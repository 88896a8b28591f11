#pragma once
// Work handed to TBB's threads, made visible to ThreadSanitizer. Debian's libtbb is not built
// with TSan, so TSan sees no happens-before edge where TBB hands a task to a worker and where
// the caller waits for it: it would report every read of the caller's data in a task as a race.
// HandOff draws those edges and no others (tasks stay unordered among themselves, so a race
// between two tasks is still reported). In other builds it is empty and costs nothing.
//
//   HandOff hand_off;
//   tbb::parallel_for(range, hand_off([&](const auto& r) { ... }));  // writes before: seen
//   hand_off.joined();                                  // every task's writes seen after this
//
// The edge into a task goes through the wrapped task's own address: every copy (TBB copies
// bodies to split them, on any thread) is released where it is made and acquired before use,
// so no member is read before its edge.
#include <utility>

#if defined(__SANITIZE_THREAD__)
extern "C" void __tsan_acquire(void* address);
extern "C" void __tsan_release(void* address);
#endif

namespace shapectl {

namespace hand_off_detail {
#if defined(__SANITIZE_THREAD__)
inline void acquire(const void* address) { __tsan_acquire(const_cast<void*>(address)); }
inline void release(const void* address) { __tsan_release(const_cast<void*>(address)); }
#else
inline void acquire(const void*) {}
inline void release(const void*) {}
#endif
}  // namespace hand_off_detail

class HandOff {
 public:
  HandOff() = default;
  HandOff(const HandOff&) = delete;
  HandOff& operator=(const HandOff&) = delete;

  template <class Task>
  class Handed {
   public:
    Handed(HandOff* hand_off, Task task) : hand_off_(hand_off), task_(std::move(task)) {
      hand_off_detail::release(this);
    }
    // hand_off_ is initialised first: the edge into `other` before its task is read.
    Handed(const Handed& other) : hand_off_(other.from()), task_(other.task_) {
      hand_off_detail::release(this);
    }
    Handed(Handed&& other) : hand_off_(other.from()), task_(std::move(other.task_)) {
      hand_off_detail::release(this);
    }
    Handed& operator=(const Handed&) = delete;

    template <class... Arguments>
    decltype(auto) operator()(Arguments&&... arguments) const {
      hand_off_detail::acquire(this);
      struct Done {  // also when the task throws
        const char* done;
        ~Done() { hand_off_detail::release(done); }
      } done{&hand_off_->done_};
      return task_(std::forward<Arguments>(arguments)...);
    }

   private:
    HandOff* from() const {
      hand_off_detail::acquire(this);
      return hand_off_;
    }
    HandOff* hand_off_;
    Task task_;
  };

  // `task` wrapped: it sees what this thread wrote before, and joined() sees what it wrote.
  template <class Task>
  Handed<Task> operator()(Task task) {
    return Handed<Task>(this, std::move(task));
  }
  // After the parallel call returned.
  void joined() const { hand_off_detail::acquire(&done_); }

 private:
  char done_ = 0;
};

}  // namespace shapectl
