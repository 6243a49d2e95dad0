// Deterministic parallel loops: every index writes only its own output slot, so the result does
// not depend on the schedule.
#pragma once

#include <tbb/parallel_for.h>

namespace wrap::detail {

/// Calls f(i) for i in [0, n), on TBB's threads when `parallel` (one index per task).
template <typename F>
void ParallelFor(int n, bool parallel, const F& f) {
  if (parallel && n > 1) {
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& r) {
      for (int i = r.begin(); i < r.end(); ++i) f(i);
    });
  } else {
    for (int i = 0; i < n; ++i) f(i);
  }
}

}  // namespace wrap::detail
