# WRAP_PCH (default ON): precompiled headers for every C++ target. About two thirds of the
# compile time of a typical source file went into parsing the standard library (~80k lines) and
# Eigen (~37k lines) it includes (g++ -ftime-report on engine/task/search.cpp: parsing 4.9 of 8.3
# s user time); they are parsed once per build instead. Two precompiled headers are made, one
# for the engine, app, ui and tools, one with GoogleTest for the test binaries; every other
# target reuses one of them (REUSE_FROM), so the build makes only two.
#
# Each header is force-included ahead of a file's own includes, so a file that forgets one of
# these includes still compiles; `-DWRAP_PCH=OFF` builds without them (what include hygiene
# checks should use). Off in WRAP_FUZZ builds (clang with its own compatibility headers).
#
# With ccache, set its sloppiness to pch_defines,time_macros (as the compiler cache's manual says
# for precompiled headers), or every file compiled with one is a cache miss.

option(WRAP_PCH "Precompiled headers (the standard library, Eigen, GoogleTest)" ON)

set(_wrap_pch_common <algorithm> <array> <chrono> <cmath> <cstdint> <cstdio> <cstdlib> <expected>
    <filesystem> <functional> <limits> <map> <memory> <numbers> <optional> <random> <set> <span>
    <sstream> <string> <string_view> <utility> <vector> <unordered_map> <deque> <fstream> <mutex>
    <thread> <Eigen/Core> <Eigen/Geometry>)

# wrap_precompiled_headers_for_targets(DIR): the precompiled headers for every C++ library and
# executable defined in DIR and below. Call once, at the end of the top-level CMakeLists.txt.
function(wrap_precompiled_headers_for_targets dir)
  if(NOT WRAP_PCH OR WRAP_FUZZ)
    return()
  endif()
  set(anchor ${CMAKE_BINARY_DIR}/wrap_pch_anchor.cpp)
  file(CONFIGURE OUTPUT ${anchor}
       CONTENT "// Generated: the source file that makes the build's precompiled headers.\n")
  add_library(wrap_pch STATIC ${anchor})
  target_link_libraries(wrap_pch PRIVATE Eigen3::Eigen wrap_warnings)
  target_precompile_headers(wrap_pch PRIVATE ${_wrap_pch_common})
  set(pch_targets wrap_pch)
  if(WRAP_BUILD_TESTS)
    # tests/CMakeLists.txt found it in its own directory scope; the header is made here.
    find_package(GTest REQUIRED)
    add_library(wrap_pch_test STATIC ${anchor})
    target_link_libraries(wrap_pch_test PRIVATE Eigen3::Eigen GTest::gtest wrap_warnings)
    target_precompile_headers(wrap_pch_test PRIVATE ${_wrap_pch_common} <gtest/gtest.h>)
    list(APPEND pch_targets wrap_pch_test)
  endif()
  _wrap_pch_reuse(${dir} "${pch_targets}")
endfunction()

# Every library or executable of `dir` and below reuses wrap_pch_test when it links GoogleTest,
# else wrap_pch. The reusing target also gets the include directories the headers come from.
function(_wrap_pch_reuse dir pch_targets)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(t IN LISTS targets)
    get_target_property(type ${t} TYPE)
    if(t IN_LIST pch_targets OR NOT type MATCHES "^(STATIC_LIBRARY|EXECUTABLE)$")
      continue()
    endif()
    get_target_property(libs ${t} LINK_LIBRARIES)
    if(libs MATCHES "GTest::" AND TARGET wrap_pch_test)
      target_link_libraries(${t} PRIVATE Eigen3::Eigen)
      target_precompile_headers(${t} REUSE_FROM wrap_pch_test)
    else()
      target_link_libraries(${t} PRIVATE Eigen3::Eigen)
      target_precompile_headers(${t} REUSE_FROM wrap_pch)
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub IN LISTS subdirs)
    _wrap_pch_reuse(${sub} "${pch_targets}")
  endforeach()
endfunction()
