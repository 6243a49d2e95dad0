#include "authoring/sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <set>

#include "mating/check.h"
#include "mating/insertion.h"

namespace wrap {

namespace {

// One way to take a unit off the rest.
struct Removal {
  std::vector<int> unit;       // the parts taken off (ascending)
  std::vector<int> rest;       // what stays
  Vec3 axis = -Vec3::UnitZ();  // the insertion axis: the unit comes back in along it
  int grasps = 0;
  double rank[6] = {0, 0, 0, 0, 0, 0};  // larger is better, compared in order
};

bool Touches(const ContactGraph& graph, const std::vector<int>& a, const std::vector<int>& b) {
  for (int p : a) {
    for (int q : b) {
      if (graph.Find(p, q)) return true;
    }
  }
  return false;
}

bool Connected(const ContactGraph& graph, const std::vector<int>& parts) {
  if (parts.size() <= 1) return true;
  std::set<int> seen = {parts[0]};
  std::vector<int> stack = {parts[0]};
  while (!stack.empty()) {
    const int p = stack.back();
    stack.pop_back();
    for (int q : graph.Neighbours(p)) {
      if (std::find(parts.begin(), parts.end(), q) != parts.end() && seen.insert(q).second) {
        stack.push_back(q);
      }
    }
  }
  return seen.size() == parts.size();
}

// How far the unit must travel to clear the rest in any direction: the diagonal of their joint
// box, plus a centimetre.
double ClearLength(AssemblyGeometry& g, const std::vector<int>& unit,
                   const std::vector<int>& rest) {
  Vec3 lo = Vec3::Constant(1e9), hi = -lo;
  for (const std::vector<int>* set : {&unit, &rest}) {
    for (int p : *set) {
      const Aabb b = g.Box(p, g.X_AP(p));
      lo = lo.cwiseMin(b.min);
      hi = hi.cwiseMax(b.max);
    }
  }
  return (hi - lo).norm() + 0.01;
}

// The best free axis of `unit` leaving `rest`, if any.
std::optional<Vec3> BestFreeAxis(AssemblyGeometry& g, const ContactGraph& graph,
                                 const std::vector<int>& unit, const std::vector<int>& rest,
                                 const SequenceOptions& options) {
  InsertionPath path;
  path.moved = unit;
  path.base = rest;
  path.length_m = ClearLength(g, unit, rest);
  path.touch_depth_m = options.touch_depth_m;
  // Axes and contact normals first; the sphere only when none of them is free.
  for (int sphere : {0, options.sphere}) {
    const std::vector<Vec3> free = FreeAxes(g, path, CandidateAxes(graph, unit, rest, sphere));
    if (free.empty()) continue;
    return *std::max_element(free.begin(), free.end(), [](const Vec3& a, const Vec3& b) {
      return AxisPreference(a) < AxisPreference(b);
    });
  }
  return std::nullopt;
}

std::optional<Removal> Evaluate(AssemblyGeometry& g, const ContactGraph& graph, GraspProbe* probe,
                                const std::vector<int>& unit, const std::vector<int>& remaining,
                                const SequenceOptions& options) {
  Removal r;
  r.unit = unit;
  for (int p : remaining) {
    if (std::find(unit.begin(), unit.end(), p) == unit.end()) r.rest.push_back(p);
  }
  if (r.rest.empty() || !Touches(graph, unit, r.rest) || !Connected(graph, r.rest)) {
    return std::nullopt;
  }
  const auto axis = BestFreeAxis(g, graph, unit, r.rest, options);
  if (!axis) return std::nullopt;
  r.axis = *axis;
  r.grasps = ClearGrasps(probe, options.end_effector, unit, r.rest);
  double z = 0.0, volume = 0.0;
  for (int p : unit) {
    const Aabb b = g.Box(p, g.X_AP(p));
    z += 0.5 * (b.min.z() + b.max.z());
    volume += b.size().prod();
  }
  // The largest part stays to the end: the base of the whole assembly (stable on the table,
  // offering the most grasps).
  int largest = remaining.front();
  for (int p : remaining) {
    if (g.query(p).area() > g.query(largest).area()) largest = p;
  }
  r.rank[0] = std::find(unit.begin(), unit.end(), largest) == unit.end() ? 1.0 : 0.0;
  r.rank[1] = r.grasps > 0 ? 1.0 : 0.0;
  r.rank[2] = AxisPreference(r.axis);
  r.rank[3] = std::round(z / unit.size() * 1000.0);  // millimetres: ties go on to size
  r.rank[4] = -volume;
  r.rank[5] = -static_cast<double>(unit.front());
  return r;
}

bool Better(const Removal& a, const Removal& b) {
  for (int k = 0; k < 6; ++k) {
    if (a.rank[k] != b.rank[k]) return a.rank[k] > b.rank[k];
  }
  return false;
}

std::string Names(const AssemblyGeometry& g, const std::vector<int>& parts) {
  std::string out;
  for (int p : parts) out += (out.empty() ? "'" : ", '") + g.name(p) + "'";
  return out;
}

// The best removal from `remaining`: single parts, else touching pairs.
std::optional<Removal> BestRemoval(AssemblyGeometry& g, const ContactGraph& graph,
                                   GraspProbe* probe, const std::vector<int>& remaining,
                                   const SequenceOptions& options) {
  std::optional<Removal> best;
  for (int p : remaining) {
    auto r = Evaluate(g, graph, probe, {p}, remaining, options);
    if (r && (!best || Better(*r, *best))) best = std::move(r);
  }
  if (best || remaining.size() < 3) return best;
  for (const Contact& c : graph.contacts) {
    if (std::find(remaining.begin(), remaining.end(), c.a) == remaining.end() ||
        std::find(remaining.begin(), remaining.end(), c.b) == remaining.end()) {
      continue;
    }
    auto r = Evaluate(g, graph, probe, {c.a, c.b}, remaining, options);
    if (r && (!best || Better(*r, *best))) best = std::move(r);
  }
  return best;
}

// The step inside a pair taken off together: the one of the two that leaves the other.
std::optional<ProposedStep> PairStep(AssemblyGeometry& g, const ContactGraph& graph,
                                     GraspProbe* probe, const std::vector<int>& pair,
                                     const SequenceOptions& options) {
  std::optional<Removal> best;
  for (int p : pair) {
    auto r = Evaluate(g, graph, probe, {p}, pair, options);
    if (r && (!best || Better(*r, *best))) best = std::move(r);
  }
  if (!best) return std::nullopt;
  ProposedStep s;
  s.moved = best->unit;
  s.base = best->rest;
  s.axis_A = best->axis;
  s.moved_grasps = best->grasps;
  return s;
}

void AssignRoles(AssemblyGeometry& g, GraspProbe* probe, const SequenceOptions& options,
                 ProposedStep& s) {
  s.base_grasps = ClearGrasps(probe, options.end_effector, s.base, s.moved);
  s.why = Names(g, s.moved) + " onto " + Names(g, s.base) + " along " + FormatDirection(s.axis_A) +
          " (" + std::to_string(s.moved_grasps) + " grasps clear of the base where mated)";
  if (probe != nullptr && s.moved_grasps == 0 && s.base_grasps > 0) {
    std::swap(s.moved, s.base);
    std::swap(s.moved_grasps, s.base_grasps);
    s.axis_A = -s.axis_A;
    s.swapped = true;
    s.why = Names(g, s.moved) + " onto " + Names(g, s.base) + " along " +
            FormatDirection(s.axis_A) +
            " (roles swapped: no grasp of the other input clears it "
            "where mated, " +
            std::to_string(s.moved_grasps) + " of this one do)";
  }
}

}  // namespace

int ClearGrasps(GraspProbe* probe, int ee, const std::vector<int>& unit,
                const std::vector<int>& rest) {
  if (probe == nullptr) return 0;
  const auto count = [&](bool reduced) {
    int n = 0;
    for (int p : unit) {
      std::vector<int> others = rest;
      for (int q : unit) {
        if (q != p) others.push_back(q);
      }
      n += reduced ? probe->ReducedClearOf(p, ee, others) : probe->ClearOf(p, ee, others);
    }
    return n;
  };
  const int full = count(false);
  return full > 0 ? full : count(true);
}

ProposedSequence ProposeSequence(AssemblyGeometry& g, const ContactGraph& graph, GraspProbe* probe,
                                 const SequenceOptions& options) {
  ProposedSequence out;
  std::vector<int> remaining;
  for (int p = 0; p < g.num_parts(); ++p) {
    if (g.has_mesh(p)) remaining.push_back(p);
  }
  std::vector<ProposedStep> removed;  // disassembly order
  while (remaining.size() > 1) {
    auto best = BestRemoval(g, graph, probe, remaining, options);
    if (!best) {
      out.interlocked = remaining;
      return out;
    }
    if (best->unit.size() == 2) {
      auto inner = PairStep(g, graph, probe, best->unit, options);
      if (!inner) {
        out.interlocked = best->unit;
        return out;
      }
      removed.push_back(*inner);
      removed.back().moved.insert(removed.back().moved.begin(), -1);  // marks the pair's step
    }
    ProposedStep s;
    s.moved = best->unit;
    s.base = best->rest;
    s.axis_A = best->axis;
    s.moved_grasps = best->grasps;
    removed.push_back(std::move(s));
    remaining = best->rest;
  }
  // Assembly order: the disassembly reversed; a pair's own step comes before the step that
  // mounts it.
  std::vector<ProposedStep> steps;
  for (auto it = removed.rbegin(); it != removed.rend(); ++it) {
    if (!it->moved.empty() && it->moved.front() == -1) continue;
    const auto next = std::next(it);
    if (it->moved.size() == 2 && next != removed.rend() && !next->moved.empty() &&
        next->moved.front() == -1) {
      ProposedStep inner = *next;
      inner.moved.erase(inner.moved.begin());
      AssignRoles(g, probe, options, inner);
      steps.push_back(std::move(inner));
    }
    ProposedStep s = *it;
    AssignRoles(g, probe, options, s);
    steps.push_back(std::move(s));
  }
  out.steps = std::move(steps);
  return out;
}

}  // namespace wrap
