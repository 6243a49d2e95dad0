// The qhull call itself, behind a C++17 interface: Debian's libqhullcpp 2020.2 headers use
// constructor names that C++20 rejects (`QhullLinkedList<T>(...)`), so qhull_adapter.cpp alone
// is compiled as C++17 (see geometry/CMakeLists.txt). Only convex_hull.cpp includes this.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace wrap::detail {

/// What qhull returned for a 3-D point set.
struct QhullOutput {
  bool ok = false;    ///< True when qhull ran to the end.
  bool flat = false;  ///< On failure: qhull found the input flat or degenerate (no volume).
  std::string error;  ///< On failure: qhull's message, on one line.
  /// Hull triangles as indices into the input points, counter-clockwise seen from outside.
  std::vector<std::array<int, 3>> triangles;
};

/// Runs qhull with joggled, hence triangulated, output ("QJ") on `count` points stored as x, y, z
/// triples.
/// Catches every QhullError (and any other exception) into the result; never throws.
QhullOutput RunQhull3d(const double* xyz, int count);

}  // namespace wrap::detail
