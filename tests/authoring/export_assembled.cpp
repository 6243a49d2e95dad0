// wrap_export_assembled PROJECT OUTDIR: writes each part's mesh, moved to its assembled pose, as
// OUTDIR/NAME.stl (metres): the example projects' meshes as a CAD export of the assembly, for
// `wrap new` (scripts/authoring_sweep.sh, the acceptance table in BENCHMARKS.md).
#include <cstdio>
#include <filesystem>

#include "geometry/mesh_export.h"
#include "model/validate.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: wrap_export_assembled PROJECT OUTDIR\n");
    return 2;
  }
  const wrap::LoadedProject lp = wrap::LoadProject(argv[1]);
  if (!lp.project || !lp.ok()) {
    std::fprintf(stderr, "%s: does not load (wrap validate says why)\n", argv[1]);
    return 2;
  }
  std::filesystem::create_directories(argv[2]);
  for (size_t i = 0; i < lp.project->parts.size(); ++i) {
    const wrap::Part& part = lp.project->parts[i];
    const auto placed = wrap::Transformed(lp.check.parts[i].mesh,
                                          wrap::ToIsometry(part.assembled_pose));
    const auto file = std::filesystem::path(argv[2]) / (part.name + ".stl");
    if (auto ok = wrap::WriteStl(file, placed); !ok) {
      std::fprintf(stderr, "%s\n", ok.error().message.c_str());
      return 2;
    }
  }
  return 0;
}
