// Helpers of the GUI document tests: the example projects and scratch folders.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <string>

#include "gui/document.h"

namespace wrap::gui::testing {

/// An example project of the repository, e.g. ExampleProject("stool").
inline std::filesystem::path ExampleProject(const std::string& name) {
  return std::filesystem::path(WRAP_SOURCE_DIR) / "projects" / (name + ".json");
}

/// A fresh empty folder for one test (under the test's temporary folder).
inline std::filesystem::path ScratchDir(const std::string& name) {
  // Per process: two test runs on one machine (two checkouts, ctest beside a CI job) must not
  // clear each other's folders mid-test.
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) /
                                    ("wrap_gui_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The stool example, opened.
inline Document OpenStool() {
  auto doc = Document::Open(ExampleProject("stool"));
  EXPECT_TRUE(doc.has_value()) << (doc ? "" : doc.error().message);
  return doc ? std::move(*doc) : Document();
}

}  // namespace wrap::gui::testing
