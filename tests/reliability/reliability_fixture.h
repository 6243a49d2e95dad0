// Shared by the reliability tests: a scratch folder per test, a small valid project written into
// it (two box parts, a catalog arm and a URDF arm), and a task-only plan of the half stool.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../app/cli_runner.h"

namespace wrap::reliability {

namespace fs = std::filesystem;

/// A fresh folder under the system's temporary folder, removed at the end of the test.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& tag) {
    std::random_device rd;
    path = fs::temp_directory_path() / ("wrap_reliability_" + tag + "_" + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path, ec);
  }
};

inline std::string ReadBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline fs::path WriteBytes(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  return file;
}

/// ASCII STL of an axis-aligned box [lo, hi] (metres), outward triangles.
inline std::string BoxStl(double x0, double y0, double z0, double x1, double y1, double z1) {
  const double v[8][3] = {{x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0},
                          {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}};
  const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                        {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  std::ostringstream s;
  s << "solid box\n";
  for (const auto& t : f) {
    s << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      s << "vertex " << v[t[k]][0] << " " << v[t[k]][1] << " " << v[t[k]][2] << "\n";
    }
    s << "endloop\nendfacet\n";
  }
  s << "endsolid box\n";
  return s.str();
}

/// A two-joint URDF arm without geometry.
inline std::string ArmUrdf() {
  const std::string limit = R"(<limit lower="-1" upper="1" velocity="1" effort="1"/>)";
  return R"(<robot name="arm"><link name="base"/><link name="a"/><link name="b"/>)"
         R"(<joint name="j1" type="revolute">)" +
         limit +
         R"(<parent link="base"/><child link="a"/></joint>)"
         R"(<joint name="j2" type="revolute">)" +
         limit + R"(<origin xyz="0 0 0.3"/><parent link="a"/><child link="b"/></joint></robot>)";
}

/// The small valid project: parts `base` (base.stl) and `peg` (peg.stl), one step, robot `r1`
/// (UR5e) and robot `r2` (arm.urdf).
inline nlohmann::json BlocksProject() {
  return nlohmann::json::parse(R"({
    "format": "wrap-project", "version": 1, "name": "blocks",
    "parts": [
      {"name": "base", "mesh": "base.stl", "mass_kg": 0.2,
       "initial_pose": {"xyz": [0, 0.1, 0.75]}},
      {"name": "peg", "mesh": "peg.stl", "mass_kg": 0.05, "assembled_pose": {"xyz": [0, 0, 0.06]},
       "initial_pose": {"xyz": [0.1, -0.1, 0.75]}}
    ],
    "steps": [{"name": "base+peg", "inputs": ["base", "peg"],
               "mating": {"moved": "peg", "base": "base", "axis": [0, 0, -1]}}],
    "robots": [
      {"name": "r1", "model": "ur5e", "end_effector": "robotiq_2f85",
       "base_pose": {"xyz": [-0.5, 0, 0.75]}},
      {"name": "r2", "urdf": "arm.urdf", "end_effector": "vacuum_cup",
       "base_pose": {"xyz": [0.5, 0, 0.75]}}
    ]})");
}

/// Writes the blocks project's meshes and URDF into `dir` (the project file itself is the
/// caller's).
inline void WriteBlocksFiles(const fs::path& dir) {
  WriteBytes(dir / "base.stl", BoxStl(-0.03, -0.03, 0, 0.03, 0.03, 0.06));
  WriteBytes(dir / "peg.stl", BoxStl(-0.01, -0.01, 0, 0.01, 0.01, 0.04));
  WriteBytes(dir / "arm.urdf", ArmUrdf());
}

/// Files in `dir` and below (temporary files of an interrupted atomic write included).
inline std::vector<std::string> ListFiles(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    names.push_back(fs::relative(it->path(), dir).string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// A task-only plan of the example `half_stool`, planned once per test binary.
inline const fs::path& HalfStoolPlan() {
  static const TempDir dir("plan");
  static const fs::path plan = [] {
    const fs::path file = dir.path / "half_stool_plan.json";
    const cli::CliRun r =
        cli::Wrap({"plan", cli::Project("half_stool"), "--task-only", "-o", file.string()});
    EXPECT_EQ(r.code, 0) << r.err;
    return file;
  }();
  return plan;
}

}  // namespace wrap::reliability
