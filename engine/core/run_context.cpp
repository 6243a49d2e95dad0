#include "core/run_context.h"

namespace wrap {

void RunContext::set_time_limit_s(double seconds) {
  if (!(seconds > 0.0) || seconds > 1e9) {
    deadline_ = Clock::time_point::max();
    return;
  }
  deadline_ = Clock::now() +
              std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace wrap
