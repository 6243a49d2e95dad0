// Replays the fuzz regression corpus (tests/fuzz/regressions: every input that once crashed,
// hung, leaked or tripped a sanitizer) and the seed corpus (tests/fuzz/seeds, the example projects
// and their meshes) through the fuzz targets' bodies. A target aborts on a broken promise, so a
// regression fails this test; under WRAP_SANITIZE the sanitizers check every input as well.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_targets.h"

namespace fs = std::filesystem;

namespace {

const fs::path kRepo = WRAP_SOURCE_DIR;
const fs::path kFuzz = kRepo / "tests/fuzz";

/// Regular files directly in `dir` (none when it does not exist), sorted, README.md excepted.
std::vector<fs::path> FilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Files under `dir` (recursively) whose extension is `ext`.
std::vector<fs::path> FilesWithExtension(const fs::path& dir, const std::string& ext) {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().extension() == ext) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

using Target = std::function<int(const uint8_t*, size_t)>;

/// Feeds every file to the target; the file's name goes to stderr first, so that a crash names it.
int Replay(const std::vector<fs::path>& files, const Target& target) {
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    EXPECT_TRUE(in.eof() || in.good()) << f;
    std::fprintf(stderr, "replay %s\n", f.c_str());
    std::fflush(stderr);
    EXPECT_EQ(target(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), 0) << f;
  }
  return static_cast<int>(files.size());
}

std::vector<fs::path> Corpus(const std::string& target) {
  std::vector<fs::path> files = FilesIn(kFuzz / "regressions" / target);
  const std::vector<fs::path> seeds = FilesIn(kFuzz / "seeds" / target);
  files.insert(files.end(), seeds.begin(), seeds.end());
  return files;
}

void Append(std::vector<fs::path>& to, const std::vector<fs::path>& more) {
  to.insert(to.end(), more.begin(), more.end());
}

}  // namespace

TEST(FuzzReplay, ProjectJson) {
  std::vector<fs::path> files = Corpus("project_json");
  Append(files, FilesWithExtension(kRepo / "projects", ".json"));
  EXPECT_GE(Replay(files, wrap::fuzz::FuzzProjectJson), 11);
}

TEST(FuzzReplay, MeshStl) {
  std::vector<fs::path> files = Corpus("mesh_stl");
  Append(files, FilesWithExtension(kRepo / "assets/parts", ".stl"));
  EXPECT_GE(
      Replay(files, [](const uint8_t* d, size_t n) { return wrap::fuzz::FuzzMesh(d, n, ".stl"); }),
      4);
}

TEST(FuzzReplay, MeshObj) {
  std::vector<fs::path> files = Corpus("mesh_obj");
  Append(files, FilesWithExtension(kRepo / "assets/parts", ".obj"));
  EXPECT_GE(
      Replay(files, [](const uint8_t* d, size_t n) { return wrap::fuzz::FuzzMesh(d, n, ".obj"); }),
      10);
}

TEST(FuzzReplay, MeshPly) {
  EXPECT_GE(Replay(Corpus("mesh_ply"),
                   [](const uint8_t* d, size_t n) { return wrap::fuzz::FuzzMesh(d, n, ".ply"); }),
            2);
}

TEST(FuzzReplay, Step) {
  std::vector<fs::path> files = Corpus("step");
  Append(files, FilesWithExtension(kRepo / "assets/parts", ".step"));
  // In this process, where the sanitizers watch Wrap's own code.
  EXPECT_GE(Replay(files,
                   [](const uint8_t* d, size_t n) {
                     return wrap::fuzz::FuzzStep(d, n, wrap::fuzz::StepProcess::kThisProcess);
                   }),
            3);
}

// Files that crash OpenCASCADE itself, imported as `wrap` does (in a child process): each must
// become an error naming the file.
TEST(FuzzReplay, StepThatCrashesOpenCascade) {
  EXPECT_GE(Replay(FilesIn(kFuzz / "regressions" / "step_crashes_occt"),
                   [](const uint8_t* d, size_t n) {
                     return wrap::fuzz::FuzzStep(d, n, wrap::fuzz::StepProcess::kChild);
                   }),
            1);
}

TEST(FuzzReplay, Urdf) { EXPECT_GE(Replay(Corpus("urdf"), wrap::fuzz::FuzzUrdf), 2); }

// The target bodies must be able to fail: a valid project whose serialisation does not parse back
// is what the project target aborts on, so a broken SerializeProject would show here. Checked
// indirectly: every example project is valid, so each one went through the round trip above.
