// Helpers of the benchmark harness tests: temporary folders, CSV reading, running the real
// `wrap` and shell scripts standing in for it.
#pragma once

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench.h"

namespace wrap::bench {

namespace fs = std::filesystem;

inline fs::path ProjectsDir() { return fs::path(WRAP_SOURCE_DIR) / "projects"; }

// A fresh folder under the system's temporary folder, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("wrap_bench_test_" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Splits a CSV line (our writer quotes fields with commas or quotes).
inline std::vector<std::string> CsvRow(const std::string& line) {
  std::vector<std::string> f(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        f.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        f.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      f.emplace_back();
    } else {
      f.back() += c;
    }
  }
  return f;
}

inline std::vector<std::vector<std::string>> ReadCsv(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) rows.push_back(CsvRow(line));
  return rows;
}

inline int Column(const std::vector<std::string>& header, const std::string& name) {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  ADD_FAILURE() << "no column " << name;
  return 0;
}

// Runs the real `wrap` with arguments; returns the exit code, stderr into `err`.
inline int RunWrap(const std::string& args, const fs::path& dir, std::string* err = nullptr) {
  const fs::path err_file = dir / "stderr.txt";
  const std::string cmd =
      std::string("'") + WRAP_EXE + "' " + args + " > /dev/null 2> '" + err_file.string() + "'";
  const int rc = std::system(cmd.c_str());
  if (err) *err = Slurp(err_file);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

inline BenchOptions TinyOptions() {
  BenchOptions o;
  o.suite = "tiny";
  o.runs = 2;
  o.time_limit_s = 10.0;
  o.jobs = 2;
  o.projects_dir = ProjectsDir();
  o.wrap_exe = WRAP_EXE;
  return o;
}

// A shell script standing in for `wrap` (classification of what a child can do).
inline fs::path FakeWrap(const fs::path& dir, const std::string& name, const std::string& body) {
  const fs::path p = dir / name;
  std::ofstream(p) << "#!/bin/sh\n" << body << "\n";
  chmod(p.c_str(), 0755);
  return p;
}

}  // namespace wrap::bench
