// `wrap [PROJECT] [--screenshot FILE.png [--run-plan] [--at T]] [--size WxH] [--script FILE]`:
// the GUI (ui/gui/app.h).
#include <cstdio>
#include <ostream>

#include "cli.h"
#include "gui/app.h"

namespace wrap::cli {

int Gui(const GuiArgs& args, std::ostream& out, std::ostream& err) {
  gui::GuiOptions options;
  options.project = args.project;
  options.screenshot = args.screenshot;
  options.run_plan = args.run_plan;
  options.at = args.at;
  options.script = args.script;
  if (!args.size.empty()) {
    int w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(args.size.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 320 || h < 240 ||
        w > 8192 || h > 8192) {
      err << "--size: expected WIDTHxHEIGHT between 320x240 and 8192x8192, got '" << args.size
          << "'\n";
      return 2;
    }
    options.width = w;
    options.height = h;
  }
  if ((args.run_plan || args.at) && args.screenshot.empty()) {
    err << "--run-plan and --at go with --screenshot\n";
    return 2;
  }
  if (args.at && !(*args.at >= 0.0)) {
    err << "--at: must be a time >= 0 [s]\n";
    return 2;
  }
  return gui::RunGui(options, out, err);
}

}  // namespace wrap::cli
