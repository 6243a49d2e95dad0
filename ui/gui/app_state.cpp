#include "gui/app_state.h"

#include <algorithm>

namespace wrap::gui {

void FrameStats::Add(double seconds, double now) {
  seconds_.push_back(seconds);
  ends_.push_back(now);
  while (seconds_.size() > kKept) {
    seconds_.pop_front();
    ends_.pop_front();
  }
}

double FrameStats::MedianFps() const {
  if (seconds_.empty()) return 0.0;
  std::vector<double> s(seconds_.begin(), seconds_.end());
  std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
  return s[s.size() / 2] > 0.0 ? 1.0 / s[s.size() / 2] : 0.0;
}

double FrameStats::RecentFps(double now) const {
  // Frames that ended within the last second, over that second (or over the time since the
  // first of them when the window has drawn for less than a second).
  int frames = 0;
  for (auto it = ends_.rbegin(); it != ends_.rend() && now - *it <= 1.0; ++it) ++frames;
  return static_cast<double>(frames);
}

std::string RunFailure::StepName() const {
  if (!failure || failure->step < 0 || failure->step >= static_cast<int>(nodes.size())) return "";
  return nodes[failure->step];
}

bool AppState::PlanStale() const {
  if (!plan || !plan_project) return false;
  return !(*plan_project == doc.project());
}

}  // namespace wrap::gui
