// SPDX-License-Identifier: Apache-2.0
#pragma once
// parallelFor: the detector's and the trainer's parallel loops, in the enclosing tbb::task_arena.
//
// Ordinary builds: exactly tbb::parallel_for. ThreadSanitizer builds (scripts/sanitize tsan): the
// same body over the same range, split into pieces run on std::threads that the call creates and
// joins. Why: Debian's libtbb is not built with TSan, so TSan does not see the happens-before
// that TBB's task queue gives (the caller's writes before the loop -> a worker's body; a body's
// writes -> the caller after the loop returns). Under TBB it reported ~900 races per run of
// boost_detector_test, in our bodies and in TBB's own header code (start_for, finalize, its
// small-object pool) alike, so no suppression could be narrow (docs/reliability.md). With
// std::thread the only edges are thread start and join, which are exactly the two that
// tbb::parallel_for promises; the pieces share no lock or atomic, so a race between two bodies,
// or between a body and any other thread of ours, is still reported.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#if defined(__SANITIZE_THREAD__)
#define FUSEDET_TSAN_LOOPS 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define FUSEDET_TSAN_LOOPS 1
#endif
#endif

#ifdef FUSEDET_TSAN_LOOPS
#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>
#endif

namespace fusedet::boosting {

#ifdef FUSEDET_TSAN_LOOPS
namespace detail {
// piece(b, e) over [first, last) in pieces of at least `grain` indices; thread t of T (the
// enclosing arena's concurrency, the caller being thread 0) runs pieces t, t + T, ... The first
// exception (by thread) is rethrown after every thread has ended.
template <class Index, class Piece>
void onStdThreads(Index first, Index last, std::size_t grain, const Piece& piece) {
  if (!(first < last)) return;
  const auto n = static_cast<std::size_t>(last - first);
  const auto concurrency = static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  const std::size_t size = std::max({std::size_t(1), grain, (n + 4 * concurrency - 1) / (4 * concurrency)});
  const std::size_t pieces = (n + size - 1) / size;
  const std::size_t threads = std::min(pieces, concurrency);
  std::vector<std::exception_ptr> errors(threads);
  auto run = [&](std::size_t t) {
    try {
      for (std::size_t p = t; p < pieces; p += threads)
        piece(first + static_cast<Index>(p * size), first + static_cast<Index>(std::min(n, (p + 1) * size)));
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::thread> others;
  for (std::size_t t = 1; t < threads; ++t) others.emplace_back(run, t);
  run(0);
  for (std::thread& t : others) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}
}  // namespace detail
#endif

// body(const tbb::blocked_range<Index>&) over every part of `range`, each index once.
template <class Index, class Body>
void parallelFor(const tbb::blocked_range<Index>& range, const Body& body) {
#ifdef FUSEDET_TSAN_LOOPS
  detail::onStdThreads(range.begin(), range.end(), range.grainsize(),
                       [&](Index b, Index e) { body(tbb::blocked_range<Index>(b, e, range.grainsize())); });
#else
  tbb::parallel_for(range, body);
#endif
}

// f(i) for every i in [first, last) (tbb::parallel_for's index form, with its partitioner).
template <class Index, class F, class Partitioner = tbb::auto_partitioner>
void parallelForEach(Index first, Index last, const F& f, const Partitioner& partitioner = Partitioner()) {
#ifdef FUSEDET_TSAN_LOOPS
  (void)partitioner;
  detail::onStdThreads(first, last, 1, [&](Index b, Index e) {
    for (Index i = b; i != e; ++i) f(i);
  });
#else
  tbb::parallel_for(first, last, f, partitioner);
#endif
}

}  // namespace fusedet::boosting
