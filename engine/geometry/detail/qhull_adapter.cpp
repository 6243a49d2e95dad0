// Compiled as C++17: see qhull_adapter.h.
#include "geometry/detail/qhull_adapter.h"

#include <libqhullcpp/Qhull.h>
#include <libqhullcpp/QhullError.h>
#include <libqhullcpp/QhullFacetList.h>
#include <libqhullcpp/QhullVertexSet.h>

#include <algorithm>
#include <exception>
#include <sstream>
#include <utility>

namespace wrap::detail {

namespace {

std::string OneLine(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace

QhullOutput RunQhull3d(const double* xyz, int count) {
  QhullOutput out;
  std::ostringstream messages;
  try {
    orgQhull::Qhull qh;
    qh.setOutputStream(&messages);
    qh.setErrorStream(&messages);
    // QJ: joggled input, so every facet is a triangle and no facet merging is needed. Qhull's
    // merging ("Qt") is quadratic on many cocircular points (a 4000-sided cylinder takes 1.5 s,
    // QJ 30 ms); the joggle (~1e-11 relative) is far below the facet merging of convex_hull.cpp.
    // Its random seed is fixed (no 'QR-1'): the same input gives the same hull. Pp: no
    // precision warnings.
    qh.runQhull("", 3, count, xyz, "QJ Pp");
    for (const orgQhull::QhullFacet& f : qh.facetList()) {
      if (!f.isGood()) continue;
      const orgQhull::QhullVertexSet vs = f.vertices();
      if (vs.size() != 3) {
        out.error = "qhull returned a facet with " + std::to_string(vs.size()) +
                    " vertices despite joggled output (QJ)";
        out.triangles.clear();
        return out;
      }
      std::array<int, 3> t = {vs[0].point().id(), vs[1].point().id(), vs[2].point().id()};
      // Orient counter-clockwise about qhull's outward facet normal.
      const double* n = f.hyperplane().coordinates();
      const double* a = xyz + 3 * t[0];
      const double* b = xyz + 3 * t[1];
      const double* c = xyz + 3 * t[2];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double cx = u[1] * v[2] - u[2] * v[1];
      const double cy = u[2] * v[0] - u[0] * v[2];
      const double cz = u[0] * v[1] - u[1] * v[0];
      if (cx * n[0] + cy * n[1] + cz * n[2] < 0.0) std::swap(t[1], t[2]);
      out.triangles.push_back(t);
    }
    out.ok = true;
  } catch (const orgQhull::QhullError& e) {
    out.error = OneLine(e.what());
    // QH6154 "initial simplex is flat", QH6214 "not enough points", QH6271 flat/narrow input.
    out.flat = out.error.find("flat") != std::string::npos ||
               out.error.find("6154") != std::string::npos ||
               out.error.find("6214") != std::string::npos ||
               out.error.find("6271") != std::string::npos;
  } catch (const std::exception& e) {
    out.error = std::string("qhull threw: ") + e.what();
  } catch (...) {
    out.error = "qhull threw an unknown exception";
  }
  return out;
}

}  // namespace wrap::detail
