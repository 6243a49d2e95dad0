// An always-on assertion for programming errors (never for anything a user's input can cause).
#pragma once

#include <cstdio>
#include <cstdlib>

/// Aborts with file, line and the failed condition when `cond` is false, in every build type.
#define WRAP_ROBOT_CHECK(cond)                                                              \
  do {                                                                                      \
    if (!(cond)) {                                                                          \
      std::fprintf(stderr, "%s:%d: internal error: check failed: %s\n", __FILE__, __LINE__, \
                   #cond);                                                                  \
      std::abort();                                                                         \
    }                                                                                       \
  } while (false)
