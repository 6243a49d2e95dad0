#include "gui/authoring_job.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <exception>

#include "authoring/layout.h"
#include "authoring/new_project.h"
#include "authoring/suggest.h"
#include "mating/insertion.h"
#include "model/validate.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

std::string Xy(const Pose& pose) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.3f, %.3f) m", pose.xyz.x(), pose.xyz.y());
  return buf;
}

void ImportAssembly(const AuthoringRequest& r, const AuthoringProgress& progress,
                    AuthoringOutcome& out) {
  NewProjectOptions options;
  options.unit = r.unit;
  options.name = r.project.name;
  if (options.name.empty() && !r.meshes.empty()) {
    const fs::path first = r.meshes.front();
    options.name = fs::is_directory(first) ? fs::absolute(first).filename().string()
                                           : first.parent_path().filename().string();
  }
  if (options.name.empty()) options.name = "assembly";
  options.progress = progress;
  auto made = NewProject(r.meshes, r.project_file, options);
  if (!made) {
    out.error = made.error().message;
    return;
  }
  out.decisions = made->decisions;
  out.project = std::move(made->project);
}

// The project's meshes read as validation reads them; false (with the reason) when one did not.
bool Checked(const Project& p, const fs::path& file, ProjectCheck& check, std::string& error) {
  check = ValidateProject(p, file);
  for (size_t i = 0; i < p.parts.size(); ++i) {
    if (i >= check.parts.size() || !check.parts[i].loaded) {
      error = "the mesh of part '" + p.parts[i].name + "' did not load (see Problems)";
      return false;
    }
  }
  return true;
}

void SuggestAssemblyOrder(const AuthoringRequest& r, const AuthoringProgress& progress,
                          AuthoringOutcome& out) {
  if (progress) progress("reading the meshes", 0.0);
  ProjectCheck check;
  if (!Checked(r.project, r.project_file, check, out.error)) return;
  if (progress) progress("finding contacts, grasps and an order", 0.2);
  auto order = SuggestOrder(r.project, check);
  if (!order) {
    out.error = order.error().message;
    return;
  }
  Project p = r.project;
  p.steps = std::move(order->steps);
  for (size_t k = 0; k < order->why.size(); ++k) {
    out.decisions.push_back("step " + std::to_string(k + 1) + ": " + order->why[k]);
  }
  out.project = std::move(p);
}

void LayOut(const AuthoringRequest& r, const AuthoringProgress& progress,
            AuthoringOutcome& out) {
  if (r.project.robots.empty()) {
    out.error = "laying out needs robots (the layout keeps every part where a robot can pick it)";
    return;
  }
  if (progress) progress("reading the meshes", 0.0);
  ProjectCheck check;
  if (!Checked(r.project, r.project_file, check, out.error)) return;
  if (!check.tree) {
    out.error = "laying out needs a well-formed assembly DAG (see Problems)";
    return;
  }
  if (progress) progress("placing the parts where robots can pick them", 0.2);
  Project p = r.project;
  auto layout = LayOutParts(p, check, r.project_file);
  if (!layout) {
    out.error = layout.error().message;
    return;
  }
  out.decisions = layout->decisions;
  for (int part : layout->unpickable) {
    out.decisions.push_back("no robot can pick '" + p.parts[part].name +
                            "' in any placement tried");
  }
  out.project = std::move(p);
}

}  // namespace

const char* ToString(AuthoringKind kind) {
  switch (kind) {
    case AuthoringKind::kImportAssembly:
      return "Import assembly";
    case AuthoringKind::kSuggestOrder:
      return "Suggest assembly order";
    case AuthoringKind::kLayOut:
      return "Lay out parts on the table";
  }
  return "";
}

AuthoringOutcome RunAuthoring(const AuthoringRequest& request,
                              const AuthoringProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  AuthoringOutcome out;
  out.kind = request.kind;
  out.revision = request.revision;
  try {
    switch (request.kind) {
      case AuthoringKind::kImportAssembly:
        ImportAssembly(request, progress, out);
        break;
      case AuthoringKind::kSuggestOrder:
        SuggestAssemblyOrder(request, progress, out);
        break;
      case AuthoringKind::kLayOut:
        LayOut(request, progress, out);
        break;
    }
  } catch (const std::exception& e) {
    out.project.reset();
    out.error = std::string("internal error: ") + e.what();
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

AuthoringJob::~AuthoringJob() {
  if (worker_.joinable()) worker_.join();
}

bool AuthoringJob::Start(AuthoringRequest request) {
  {
    std::lock_guard lock(mutex_);
    if (running_) return false;
    running_ = true;
    kind_ = request.kind;
    stage_ = "starting";
    fraction_ = 0.0;
    outcome_.reset();
  }
  if (worker_.joinable()) worker_.join();
  worker_ = std::jthread([this, r = std::move(request)](std::stop_token) {
    // Below the window in priority, like the planner and the live validation.
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
    AuthoringOutcome out = RunAuthoring(r, [this](const std::string& stage, double fraction) {
      std::lock_guard lock(mutex_);
      stage_ = stage;
      fraction_ = fraction;
    });
    std::lock_guard lock(mutex_);
    outcome_ = std::move(out);
  });
  return true;
}

bool AuthoringJob::running() const {
  std::lock_guard lock(mutex_);
  return running_;
}

AuthoringKind AuthoringJob::kind() const {
  std::lock_guard lock(mutex_);
  return kind_;
}

std::string AuthoringJob::stage() const {
  std::lock_guard lock(mutex_);
  return stage_;
}

double AuthoringJob::fraction() const {
  std::lock_guard lock(mutex_);
  return fraction_;
}

std::optional<AuthoringOutcome> AuthoringJob::Take() {
  std::lock_guard lock(mutex_);
  if (!outcome_) return std::nullopt;
  std::optional<AuthoringOutcome> out = std::move(outcome_);
  outcome_.reset();
  running_ = false;
  return out;
}

std::vector<std::string> DescribeChanges(const Project& before, const Project& after) {
  std::vector<std::string> out;
  auto find_part = [](const Project& p, const std::string& name) -> const Part* {
    for (const Part& q : p.parts) {
      if (q.name == name) return &q;
    }
    return nullptr;
  };
  for (const Part& q : after.parts) {
    const Part* old = find_part(before, q.name);
    if (!old) {
      out.push_back("part '" + q.name + "' added (" + q.mesh + ")");
    } else if (!(old->initial_pose == q.initial_pose)) {
      out.push_back("part '" + q.name + "' moved on the table from " + Xy(old->initial_pose) +
                    " to " + Xy(q.initial_pose) +
                    (old->initial_pose.rpy == q.initial_pose.rpy ? "" : ", turned"));
    }
  }
  for (const Part& q : before.parts) {
    if (!find_part(after, q.name)) out.push_back("part '" + q.name + "' removed");
  }
  auto find_step = [](const Project& p, const std::string& name) -> const Step* {
    for (const Step& s : p.steps) {
      if (s.name == name) return &s;
    }
    return nullptr;
  };
  for (const Step& s : after.steps) {
    const Step* old = find_step(before, s.name);
    const std::string what = "'" + s.mating.moved + "' onto '" + s.mating.base + "' along " +
                             FormatDirection(s.mating.axis.normalized());
    if (!old) {
      out.push_back("step '" + s.name + "' added: " + what);
    } else if (!(*old == s)) {
      out.push_back("step '" + s.name + "' changed: " + what);
    }
  }
  for (const Step& s : before.steps) {
    if (!find_step(after, s.name)) out.push_back("step '" + s.name + "' removed");
  }
  auto has_robot = [](const Project& p, const std::string& name) {
    for (const Robot& r : p.robots) {
      if (r.name == name) return true;
    }
    return false;
  };
  for (const Robot& r : after.robots) {
    if (!has_robot(before, r.name)) out.push_back("robot '" + r.name + "' added (" + r.model + ")");
  }
  for (const Robot& r : before.robots) {
    if (!has_robot(after, r.name)) out.push_back("robot '" + r.name + "' removed");
  }
  if (!(before.table == after.table)) out.push_back("table resized for the robots");
  return out;
}

Command ApplyAuthoring(const AuthoringOutcome& outcome) {
  Command c;
  switch (outcome.kind) {
    case AuthoringKind::kImportAssembly:
      c.label = "import assembly (" +
                std::to_string(outcome.project ? outcome.project->parts.size() : 0) + " parts)";
      break;
    case AuthoringKind::kSuggestOrder:
      c.label = "suggest assembly order";
      break;
    case AuthoringKind::kLayOut:
      c.label = "lay out parts on the table";
      break;
  }
  auto project = std::make_shared<const std::optional<Project>>(outcome.project);
  c.apply = [project, label = c.label](Project& p) -> Result<void> {
    if (!*project) return Fail(ErrorCode::kInvalidInput, label + ": nothing to apply");
    p = **project;
    return {};
  };
  return c;
}

}  // namespace wrap::gui
