#include "gui/geometry_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "gui/commands.h"
#include "mating/insertion.h"

namespace wrap::gui {

namespace {

const StepGeometry* StepOf(const GeometryReport& report, int s) {
  for (const StepGeometry& g : report.steps) {
    if (g.step == s) return &g;
  }
  return nullptr;
}

int PartIndex(const Project& p, const std::string& name) {
  for (size_t i = 0; i < p.parts.size(); ++i) {
    if (p.parts[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// The 8 corners of a box.
std::vector<Vec3> Corners(const Aabb& box) {
  std::vector<Vec3> out;
  for (int k = 0; k < 8; ++k) {
    out.emplace_back(k & 1 ? box.max.x() : box.min.x(), k & 2 ? box.max.y() : box.min.y(),
                     k & 4 ? box.max.z() : box.min.z());
  }
  return out;
}

// The 12 edges of a box shifted by `shift`.
void BoxEdges(const Aabb& box, const Vec3& shift, SweepSegment::Kind kind,
              std::vector<SweepSegment>& out) {
  const std::vector<Vec3> c = Corners(box);
  for (int a = 0; a < 8; ++a) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (a & bit) continue;
      out.push_back({c[a] + shift, c[a | bit] + shift, kind});
    }
  }
}

}  // namespace

std::optional<StepVerdict> FindStepVerdict(const ValidationResult& result, const Step& step) {
  if (!result.geometry || !result.project) return std::nullopt;
  const Project& checked = *result.project;
  for (size_t s = 0; s < checked.steps.size(); ++s) {
    if (checked.steps[s].name != step.name) continue;
    if (!(checked.steps[s] == step)) return std::nullopt;
    const StepGeometry* g = StepOf(*result.geometry, static_cast<int>(s));
    if (!g) return std::nullopt;
    return StepVerdict{g, &checked};
  }
  return std::nullopt;
}

std::vector<std::string> TouchingParts(const ValidationResult& result, const std::string& part) {
  std::vector<std::string> out;
  if (!result.geometry || !result.project) return out;
  const Project& checked = *result.project;
  const int p = PartIndex(checked, part);
  if (p < 0) return out;
  for (int q : result.geometry->contacts.Neighbours(p)) {
    if (q < 0 || q >= static_cast<int>(checked.parts.size())) continue;
    const Contact* c = result.geometry->contacts.Find(p, q);
    char buf[64];
    std::snprintf(buf, sizeof buf, " (%.1f cm2)", c ? c->area_m2 * 1e4 : 0.0);
    out.push_back(checked.parts[q].name + buf);
  }
  return out;
}

bool PartsTouch(const ValidationResult& result, const std::string& a, const std::string& b) {
  if (!result.geometry || !result.project) return false;
  const int p = PartIndex(*result.project, a), q = PartIndex(*result.project, b);
  return p >= 0 && q >= 0 && result.geometry->contacts.Find(p, q) != nullptr;
}

std::vector<Vec3> RankedFreeDirections(const StepGeometry& geometry) {
  std::vector<Vec3> out = geometry.free_axes;
  std::stable_sort(out.begin(), out.end(), [](const Vec3& a, const Vec3& b) {
    return AxisPreference(a) > AxisPreference(b);
  });
  return out;
}

std::string PathVerdictText(const StepVerdict& verdict, const Step& step) {
  const StepGeometry& g = *verdict.geometry;
  const Project& p = *verdict.checked;
  auto name = [&](int part) {
    return part >= 0 && part < static_cast<int>(p.parts.size()) ? "'" + p.parts[part].name + "'"
                                                                : std::string("a part");
  };
  if (!g.touch) {
    return "the inputs do not touch where mated (closest " + FormatMm(g.inputs.distance_m) +
           " apart)";
  }
  for (size_t k = 0; k < g.paths.size(); ++k) {
    const PathHit& hit = g.paths[k];
    if (!hit.blocked) continue;
    return "blocked: " + name(hit.moved_part) + " moving along " +
           FormatDirection(step.mating.axis.normalized()) + " hits " + name(hit.base_part) + " " +
           FormatMm(hit.at_m) + " before its mating pose" +
           (g.paths.size() > 1 ? " (final pose " + std::to_string(k + 1) + ")" : "");
  }
  return "free along " + FormatDirection(step.mating.axis.normalized()) + " (" +
         FormatMm(step.mating.approach_m) + " of approach swept against the base)";
}

Command UseInsertionAxis(const std::string& step, const Vec3& axis) {
  Command c;
  const Vec3 unit = axis.norm() > 1e-9 ? Vec3(axis.normalized()) : axis;
  c.label = "use insertion axis " + FormatDirection(unit) + " for step '" + step + "'";
  c.apply = [step, axis](Project& p) -> Result<void> {
    for (Step& s : p.steps) {
      if (s.name != step) continue;
      if (!(axis.norm() > 1e-9)) return Fail(ErrorCode::kInvalidInput, "a zero axis");
      s.mating.axis = axis.normalized();
      return {};
    }
    return Fail(ErrorCode::kInvalidInput, "there is no step '" + step + "'");
  };
  return c;
}

Iso3 AssembledPlacement(const Table& table, const std::vector<Aabb>& boxes_A) {
  Aabb all;
  all.min = Vec3::Constant(std::numeric_limits<double>::infinity());
  all.max = -all.min;
  for (const Aabb& b : boxes_A) {
    all.min = all.min.cwiseMin(b.min);
    all.max = all.max.cwiseMax(b.max);
  }
  Iso3 X_WA = Iso3::Identity();
  if (!(all.min.x() <= all.max.x())) {
    X_WA.translation() = Vec3(table.center_xy.x(), table.center_xy.y(), table.height);
    return X_WA;
  }
  const Vec3 centre = 0.5 * (all.min + all.max);
  X_WA.translation() = Vec3(table.center_xy.x() - centre.x(), table.center_xy.y() - centre.y(),
                            table.height - all.min.z());
  return X_WA;
}

std::vector<SweepSegment> InsertionSweep(const Aabb& moved_box_A, const Vec3& axis_A,
                                         double length_m, double blocked_at_m) {
  std::vector<SweepSegment> out;
  if (!(axis_A.norm() > 1e-9) || !(length_m > 0.0)) return out;
  const Vec3 u = axis_A.normalized();
  // The moved input travels along u into its mating pose: s back along the path is -s u.
  BoxEdges(moved_box_A, -length_m * u, SweepSegment::Kind::kOutline, out);
  BoxEdges(moved_box_A, Vec3::Zero(), SweepSegment::Kind::kOutline, out);
  const bool blocked = blocked_at_m >= 0.0;
  const double hit = blocked ? std::min(blocked_at_m, length_m) : 0.0;
  if (blocked) BoxEdges(moved_box_A, -hit * u, SweepSegment::Kind::kBlocked, out);
  for (const Vec3& c : Corners(moved_box_A)) {
    if (length_m > hit) out.push_back({c - length_m * u, c - hit * u, SweepSegment::Kind::kFree});
    if (blocked && hit > 0.0) out.push_back({c - hit * u, c, SweepSegment::Kind::kBlocked});
  }
  return out;
}

}  // namespace wrap::gui
