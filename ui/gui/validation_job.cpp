#include "gui/validation_job.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <exception>

#include "mating/project_check.h"

namespace wrap::gui {

LiveValidation::~LiveValidation() {
  if (worker_.joinable()) worker_.join();
}

void LiveValidation::Update(const Project& project, unsigned long revision,
                            const std::filesystem::path& project_file, double now,
                            bool now_please) {
  if (revision != seen_revision_) {
    seen_revision_ = revision;
    seen_at_ = now;
  }
  {
    std::lock_guard lock(mutex_);
    if (running_ || started_revision_ == revision) return;
  }
  if (!now_please && now - seen_at_ < quiet_s_) return;
  Start(project, revision, project_file);
}

void LiveValidation::Start(const Project& project, unsigned long revision,
                           const std::filesystem::path& project_file) {
  if (worker_.joinable()) worker_.join();
  {
    std::lock_guard lock(mutex_);
    running_ = true;
    started_revision_ = revision;
  }
  auto snapshot = std::make_shared<const Project>(project);
  worker_ = std::jthread([this, snapshot, revision, file = project_file](std::stop_token) {
    // Below the window in priority, like the planner (see PlannerJob::Run).
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
    const auto t0 = std::chrono::steady_clock::now();
    ValidationResult r;
    r.revision = revision;
    r.project = snapshot;
    try {
      auto geometry = std::make_shared<GeometryReport>();
      r.diagnostics = CheckProject(*snapshot, file, geometry.get()).diagnostics;
      r.geometry = std::move(geometry);
    } catch (const std::exception& e) {
      r.diagnostics.Error(file.string(), "",
                          std::string("internal error while checking: ") + e.what());
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::lock_guard lock(mutex_);
    result_ = std::move(r);
    running_ = false;
  });
}

ValidationResult LiveValidation::result() const {
  std::lock_guard lock(mutex_);
  return result_;
}

bool LiveValidation::pending() const {
  std::lock_guard lock(mutex_);
  return running_ || started_revision_ != seen_revision_;
}

unsigned long LiveValidation::checked_revision() const {
  std::lock_guard lock(mutex_);
  return result_.revision;
}

}  // namespace wrap::gui
