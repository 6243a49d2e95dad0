#include <cmath>
#include <cstdio>
#include <numbers>
#include <ostream>

#include "cli.h"
#include "core/file_io.h"
#include "core/run_context.h"
#include "grasp/preprocess.h"
#include "grasp/preprocess_json.h"
#include "load.h"

namespace wrap::cli {

namespace {

void PrintSubassembly(const Project& p, const Subassembly& s, std::ostream& out) {
  out << "  " << s.name << "  (" << s.parts.size() << (s.parts.size() == 1 ? " part" : " parts");
  if (s.parts.size() > 1) {
    out << ":";
    for (size_t k = 0; k < s.parts.size(); ++k) out << (k ? ", " : " ") << p.parts[s.parts[k]].name;
  }
  out << "; " << Fmt("%.4f", s.mass_kg) << " kg)\n";
  out << "      placements " << s.placements.size();
  if (!s.placements.empty()) {
    const StablePlacement& best = s.placements.front();
    out << " (most stable: tip angle " << Fmt("%.1f", best.tip_angle_rad * 180.0 / std::numbers::pi)
        << " deg, margin " << Fmt("%.1f", best.margin_m * 1000.0) << " mm)";
  }
  out << "\n      grasps";
  for (size_t e = 0; e < s.grasp_sets.size(); ++e) {
    const GraspSet& set = s.grasp_sets[e];
    out << (e ? ", " : " ") << set.end_effector << " " << set.grasps.size() << " (of "
        << set.candidates << " candidates)";
  }
  out << "\n";
}

}  // namespace

int Preprocess(const PreprocessArgs& args, std::ostream& out, std::ostream& err) {
  const LoadedProject loaded = LoadChecked(args.project);
  if (!ReportLoad(loaded, args.project, err)) return 2;
  const Project& p = *loaded.project;
  PreprocessOptions options;
  options.project_file = args.project;
  options.grasps = args.grasps;
  if (args.slots >= 0) options.table_slots.num_slots = args.slots;
  RunContext ctx(args.seed.value_or(p.planner.seed));
  UseLog(ctx, err);
  auto result = wrap::Preprocess(p, loaded.check, options, ctx);
  if (!result) {
    err << args.project << ": " << result.error().message << "\n";
    return ExitCodeFor(result.error().code);
  }
  const Preprocessed& r = *result;
  for (const std::string& w : r.warnings) err << args.project << ": warning: " << w << "\n";

  out << "Preprocessed '" << p.name << "': " << r.subassemblies.size() << " subassemblies, "
      << r.grasps_per_set << " grasps per set, friction " << Fmt("%.2f", r.friction) << ", seed "
      << args.seed.value_or(p.planner.seed) << "\n";
  out << "\nTable slots: " << r.table_slots.slots.size() << " (of " << r.table_slots.reachable
      << " reachable grid points, " << r.table_slots.candidates << " tried), "
      << r.table_slots.yaws_rad.size() << " yaws each\n";
  for (const TableSlot& slot : r.table_slots.slots) {
    char xy[64];
    std::snprintf(xy, sizeof xy, "(%.3f, %.3f)", slot.p_W.x(), slot.p_W.y());
    out << "  " << xy << " m, reached by";
    for (int robot : slot.robots) out << " " << p.robots[robot].name;
    out << "\n";
  }
  out << "\nSubassemblies (parts first, then steps):\n";
  for (const Subassembly& s : r.subassemblies) PrintSubassembly(p, s, out);
  out << "\nTimings [s]:";
  for (const char* key : {"subassemblies", "hulls", "placements", "table_slots", "grasp_candidates",
                          "grasp_sets", "reduced_grasps"}) {
    if (auto it = r.times.find(key); it != r.times.end())
      out << " " << key << " " << Fmt("%.3f", it->second);
  }
  out << "; total (t_grasp) " << Fmt("%.3f", r.times.contains("total") ? r.times.at("total") : 0.0)
      << "\n";

  if (!args.output.empty()) {
    if (auto written = WriteFileAtomic(args.output, PreprocessedToJson(p, r)); !written) {
      err << args.output << ": " << written.error().message << "\n";
      return ExitCodeFor(written.error().code);
    }
    out << "Wrote " << args.output << "\n";
  }
  return 0;
}

}  // namespace wrap::cli
