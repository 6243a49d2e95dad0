// Running an import in a child process, so that a crash inside OpenCASCADE on a damaged file
// becomes an error ("OpenCASCADE crashed on it") instead of taking Wrap (and the user's unsaved
// work in the GUI) down with it. OpenCASCADE 7.6 dereferences null or mistyped entities of some
// damaged files (found by fuzz_step); no check before the reader can foresee every one.
#pragma once

#include <functional>
#include <mutex>
#include <string>

#include "core/result.h"
#include "geometry/step_import.h"

namespace wrap::detail {

/// Runs `import` in a forked child process and returns what it returned, sent back through a
/// pipe. `held` is locked around the fork, so that no other thread of this process is inside
/// the library `import` uses at that moment (the child inherits it locked: `import` must not lock
/// it again; it is the child's only thread). A child that dies by a signal, or exits before it
/// has sent a complete answer (a sanitizer's report, an exception nobody caught), gives
/// kInvalidInput: "cannot read STEP file 'FILE': OpenCASCADE crashed on it (SIGSEGV: ...)". A
/// child that cannot be started gives kIo. The child writes no core file and runs no exit
/// handlers.
Result<StepAssembly> ImportInChild(const std::string& file,
                                   const std::function<Result<StepAssembly>()>& import,
                                   std::mutex& held);

}  // namespace wrap::detail
