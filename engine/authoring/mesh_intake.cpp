#include "authoring/mesh_intake.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

#include "geometry/mesh_import.h"
#include "geometry/step_import.h"

namespace wrap {

namespace fs = std::filesystem;

namespace {

constexpr double kTypicalSize_m = 0.2;  // a table-top assembly: what `auto` aims for

bool IsMeshFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  static const std::set<std::string> kExts = {".stl", ".obj", ".ply", ".off", ".3mf",
                                              ".dae", ".gltf", ".glb"};
  return kExts.contains(ext);
}

Result<std::vector<fs::path>> ListFiles(const std::vector<fs::path>& inputs) {
  std::vector<fs::path> files;
  for (const fs::path& in : inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      std::vector<fs::path> found;
      for (const fs::directory_entry& e : fs::directory_iterator(in, ec)) {
        if (e.is_regular_file() && IsMeshFile(e.path())) found.push_back(e.path());
      }
      if (ec) return Fail(ErrorCode::kIo, "cannot list '" + in.string() + "': " + ec.message());
      std::sort(found.begin(), found.end());
      if (found.empty()) {
        return Fail(ErrorCode::kInvalidInput,
                    "'" + in.string() + "' holds no mesh file (STL, OBJ, PLY, OFF, 3MF, DAE, glTF)");
      }
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(in, ec)) {
      files.push_back(in);
    } else {
      return Fail(ErrorCode::kIo, "mesh file '" + in.string() + "' not found");
    }
  }
  return files;
}

// The unit making the largest extent `size` (file units) closest to a table-top assembly.
LengthUnit PickUnit(double size, std::string* why) {
  const std::pair<LengthUnit, double> units[] = {
      {LengthUnit::kMillimetre, 1e-3}, {LengthUnit::kCentimetre, 1e-2}, {LengthUnit::kMetre, 1.0}};
  LengthUnit best = LengthUnit::kMetre;
  double best_err = std::numeric_limits<double>::infinity();
  std::string sizes;
  for (const auto& [unit, scale] : units) {
    const double err = std::abs(std::log10(size * scale / kTypicalSize_m));
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%.3g m in %s", sizes.empty() ? "" : ", ", size * scale,
                  ToString(unit));
    sizes += buf;
    if (err < best_err) {
      best_err = err;
      best = unit;
    }
  }
  *why = "the assembly's largest extent is " + sizes + "; " + ToString(best) +
         " is the closest to a table-top assembly";
  return best;
}

double ScaleOf(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kMillimetre:
      return 1e-3;
    case LengthUnit::kCentimetre:
      return 1e-2;
    default:
      return 1.0;
  }
}

// One part per leaf instance of a STEP assembly file, in the assembly frame.
Result<MeshIntake> ReadStepAssembly(const fs::path& file, LengthUnit unit) {
  auto assembly = ImportStep(file);
  if (!assembly) return std::unexpected(assembly.error());
  if (assembly->instances.size() < 2) {
    return Fail(ErrorCode::kInvalidInput,
                "'" + file.string() + "' holds " + std::to_string(assembly->instances.size()) +
                    " part: an assembly needs at least two (a STEP assembly file, or one mesh "
                    "file per part)");
  }
  MeshIntake out;
  for (const StepInstance& inst : assembly->instances) {
    const StepSolid& solid = assembly->solids[static_cast<size_t>(inst.solid)];
    out.names.push_back(inst.name);
    out.files.push_back(file);
    out.meshes.push_back(Transformed(solid.mesh, inst.X_AS));
    out.solids.push_back(solid.name);
    out.X_AP.push_back(inst.X_AS);
    out.colors.push_back(inst.color);
  }
  out.unit = LengthUnit::kMetre;
  out.scale = 1.0;
  out.unit_reason = "the STEP file's own unit (" + assembly->unit + "), converted to metres" +
                    (unit == LengthUnit::kAuto ? "" : "; --unit does not apply to STEP");
  return out;
}

}  // namespace

const char* ToString(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kAuto:
      return "auto";
    case LengthUnit::kMillimetre:
      return "mm";
    case LengthUnit::kCentimetre:
      return "cm";
    case LengthUnit::kMetre:
      return "m";
  }
  return "?";
}

Result<LengthUnit> ParseLengthUnit(const std::string& text) {
  for (LengthUnit u : {LengthUnit::kAuto, LengthUnit::kMillimetre, LengthUnit::kCentimetre,
                       LengthUnit::kMetre}) {
    if (text == ToString(u)) return u;
  }
  return Fail(ErrorCode::kInvalidInput,
              "--unit: expected auto, mm, cm or m, found '" + text + "'");
}

Result<MeshIntake> ReadAssemblyMeshes(const std::vector<fs::path>& inputs, LengthUnit unit) {
  auto files = ListFiles(inputs);
  if (!files) return std::unexpected(files.error());
  if (files->empty()) return Fail(ErrorCode::kInvalidInput, "no mesh files given");
  if (files->size() == 1 && LooksLikeStep(files->front())) {
    return ReadStepAssembly(files->front(), unit);
  }
  if (files->size() == 1) {
    return Fail(ErrorCode::kInvalidInput,
                "only one mesh ('" + files->front().string() +
                    "'): an assembly needs at least two parts, one file per part");
  }
  MeshIntake out;
  std::set<std::string> taken;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const fs::path& f : *files) {
    auto mesh = ImportMesh(f, MeshImportOptions{});
    if (!mesh) return std::unexpected(mesh.error());
    const MeshTopology topo = AnalyzeTopology(*mesh);
    if (!topo.closed()) {
      return Fail(ErrorCode::kInvalidInput,
                  "mesh '" + f.string() + "' is not closed (" +
                      std::to_string(topo.boundary_edges) + " boundary edges, " +
                      std::to_string(topo.non_manifold_edges) +
                      " non-manifold edges): contacts, mass and overlaps need solid parts; "
                      "repair or re-export it as a closed solid");
    }
    const Aabb box = ComputeAabb(*mesh);
    lo = lo.cwiseMin(box.min);
    hi = hi.cwiseMax(box.max);
    std::string name = f.stem().string();
    for (int k = 2; taken.contains(name); ++k) name = f.stem().string() + "_" + std::to_string(k);
    taken.insert(name);
    out.names.push_back(name);
    out.files.push_back(f);
    out.meshes.push_back(std::move(*mesh));
    out.solids.emplace_back();
    out.X_AP.push_back(Iso3::Identity());
    out.colors.emplace_back();
  }
  out.unit = unit;
  if (unit == LengthUnit::kAuto) {
    out.unit = PickUnit((hi - lo).maxCoeff(), &out.unit_reason);
  } else {
    out.unit_reason = "as given";
  }
  out.scale = ScaleOf(out.unit);
  for (TriangleMesh& m : out.meshes) {
    for (Vec3& v : m.vertices) v *= out.scale;
  }
  return out;
}

}  // namespace wrap
