// Threading helpers of the CPU backend.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__SANITIZE_THREAD__)
#define ELO_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define ELO_THREAD_SANITIZER 1
#endif
#endif
#ifdef ELO_THREAD_SANITIZER
#include <sanitizer/tsan_interface.h>
#endif

namespace elo::cpu {

// TBB starts and joins its tasks inside libtbb, which ThreadSanitizer cannot see (Debian's TBB is not
// instrumented), so a TSan build would report every value a task writes and the caller reads after the
// loop. These annotations state what tbb::parallel_for guarantees and no more: what the caller did
// before the loop happens before every task, and every task happens before the loop returns. Tasks
// gain no order among themselves, so a race between two tasks is still reported. No-ops otherwise.
class ForkJoinOrder {
 public:
#ifdef ELO_THREAD_SANITIZER
  // `task` is what the loop hands its threads. Its address escapes only at the loop, so the compiler
  // may still be storing into it after the release; the empty asm that takes its address forbids that.
  template <typename Task>
  void beforeLoop(const Task& task) {
    asm volatile("" : : "g"(&task) : "memory");
    __tsan_release(&fork_token_);
  }
  // Static, so that a task acquires before it reads anything of the loop, even its captures. The one
  // token also orders tasks after other threads' loop starts; only callers on several threads notice.
  static void taskStarts() { __tsan_acquire(&fork_token_); }
  void taskEnds() { __tsan_release(&join_); }
  void afterLoop() { __tsan_acquire(&join_); }

 private:
  inline static char fork_token_ = 0;
  char join_ = 0;
#else
  template <typename Task>
  void beforeLoop(const Task&) {}
  static void taskStarts() {}
  void taskEnds() {}
  void afterLoop() {}
#endif
};

// The fixed blocks of deterministicSum() and parallelSelect(): small enough that the 10,000 to 100,000
// elements of a scan's loops give every thread of a 16-core machine several blocks, large enough that a
// block's fork costs little against its work.
constexpr size_t kFixedBlock = 1024;

// Sums `body(begin, end, partial)` over [0, count) in fixed blocks and adds the block results in block
// order. The result is therefore the same bit for bit whatever the number of threads, so trajectories
// are reproducible across machines, thread counts and runs.
template <typename Sum, typename Body>
Sum deterministicSum(size_t count, const Body& body) {
  constexpr size_t kBlock = kFixedBlock;
  const size_t blocks = (count + kBlock - 1) / kBlock;
  std::vector<Sum> partials(blocks);
  ForkJoinOrder order;
  const auto sum_block = [&](size_t block) {
    ForkJoinOrder::taskStarts();
    body(block * kBlock, std::min(count, (block + 1) * kBlock), partials[block]);
    order.taskEnds();
  };
  order.beforeLoop(sum_block);
  tbb::parallel_for(size_t{0}, blocks, sum_block);
  order.afterLoop();
  Sum total{};
  for (const Sum& partial : partials) total += partial;
  return total;
}

// The indices i in [0, count) for which `keep(i)` holds, in increasing order, into `selected`: each
// fixed block counts its kept indices, the counts place the blocks one after another, and each block
// writes its own, so the list is found in parallel and comes out the same whatever the thread count.
template <typename Keep>
void parallelSelect(size_t count, const Keep& keep, std::vector<int32_t>& selected) {
  constexpr size_t kBlock = kFixedBlock;
  const size_t blocks = (count + kBlock - 1) / kBlock;
  std::vector<size_t> first(blocks + 1, 0);  // first[b + 1]: block b's count, then where it starts
  ForkJoinOrder counting;
  const auto count_block = [&](size_t block) {
    ForkJoinOrder::taskStarts();
    size_t kept = 0;
    for (size_t i = block * kBlock; i < std::min(count, (block + 1) * kBlock); ++i) kept += keep(i) ? 1 : 0;
    first[block + 1] = kept;
    counting.taskEnds();
  };
  counting.beforeLoop(count_block);
  tbb::parallel_for(size_t{0}, blocks, count_block);
  counting.afterLoop();
  for (size_t block = 0; block < blocks; ++block) first[block + 1] += first[block];
  selected.resize(first[blocks]);
  ForkJoinOrder writing;
  const auto write_block = [&](size_t block) {
    ForkJoinOrder::taskStarts();
    size_t at = first[block];
    for (size_t i = block * kBlock; i < std::min(count, (block + 1) * kBlock); ++i) {
      if (keep(i)) selected[at++] = static_cast<int32_t>(i);
    }
    writing.taskEnds();
  };
  writing.beforeLoop(write_block);
  tbb::parallel_for(size_t{0}, blocks, write_block);
  writing.afterLoop();
}

// Runs `first()` and `second()` side by side in the current arena (each may run parallel loops of its
// own), returning when both have.
template <typename First, typename Second>
void parallelInvoke(const First& first, const Second& second) {
  ForkJoinOrder order;
  const auto run_first = [&] {
    ForkJoinOrder::taskStarts();
    first();
    order.taskEnds();
  };
  const auto run_second = [&] {
    ForkJoinOrder::taskStarts();
    second();
    order.taskEnds();
  };
  order.beforeLoop(run_first);
  order.beforeLoop(run_second);
  tbb::parallel_invoke(run_first, run_second);
  order.afterLoop();
}

// Whether the loops of the current arena run on one thread only (a backend with `runtime.threads` 1).
inline bool runsAlone() { return tbb::this_task_arena::max_concurrency() == 1; }

// Runs `body(begin, end)` over blocks that split [0, count) across the threads of the current arena, for
// loops that look ahead within their block (prefetches). TBB sizes the blocks from the thread count and
// splits them further as threads fall idle; no minimum size is set, so that a loop over few heavy items
// (image rows or columns, blocks of pixels) spreads over every thread too.
template <typename Body>
void parallelForBlocks(size_t count, const Body& body) {
  ForkJoinOrder order;
  const auto run_range = [&](const tbb::blocked_range<size_t>& range) {
    ForkJoinOrder::taskStarts();
    body(range.begin(), range.end());
    order.taskEnds();
  };
  order.beforeLoop(run_range);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count), run_range);
  order.afterLoop();
}

// Runs `body(i)` for every i in [0, count) across the threads of the current arena.
template <typename Body>
void parallelFor(size_t count, const Body& body) {
  parallelForBlocks(count, [&](size_t begin, size_t end) {
    for (size_t i = begin; i != end; ++i) body(i);
  });
}

}  // namespace elo::cpu
