// wrap_make_parts OUT_DIR: writes the team's benchmark part meshes (stool, chair, cross, cube) to
// OUT_DIR/<assembly>/<part>.<stl|obj>, in millimetres, and the STEP stool assembly to
// OUT_DIR/step/stool.step (with OpenCASCADE). The committed copy lives in assets/parts.
#include <cstdio>
#include <filesystem>

#include "generator/part_designs.h"
#include "generator/step_designs.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr,
                 "usage: wrap_make_parts OUT_DIR\n"
                 "Writes every generated part mesh to OUT_DIR/<assembly>/<part>.<stl|obj> "
                 "(millimetres).\n");
    return 2;
  }
  const std::filesystem::path out_dir = argv[1];
  const auto parts = wrap::partgen::GenerateParts();
  if (!parts) {
    std::fprintf(stderr, "wrap_make_parts: %s\n", parts.error().message.c_str());
    return 3;
  }
  for (const wrap::partgen::GeneratedPart& part : *parts) {
    if (auto ok = wrap::partgen::WritePart(out_dir, part); !ok) {
      std::fprintf(stderr, "wrap_make_parts: %s\n", ok.error().message.c_str());
      return 2;
    }
    std::printf("%s: %zu triangles\n", (out_dir / part.RelativePath()).string().c_str(),
                part.mesh.triangles.size());
  }
  const std::filesystem::path step = out_dir / wrap::partgen::kStepStoolFile;
  if (!wrap::StepImportAvailable()) {
    std::printf("%s: skipped (built without OpenCASCADE)\n", step.string().c_str());
    return 0;
  }
  std::filesystem::create_directories(step.parent_path());
  if (auto ok = wrap::WriteStep(wrap::partgen::StepStoolSpec(), step); !ok) {
    std::fprintf(stderr, "wrap_make_parts: %s\n", ok.error().message.c_str());
    return 2;
  }
  std::printf("%s: STEP assembly\n", step.string().c_str());
  return 0;
}
