# WRAP_SANITIZE: build every target (engine, app, ui, tests, tools) with AddressSanitizer and
# UndefinedBehaviorSanitizer. UBSan does not recover (-fno-sanitize-recover=all): its first report
# aborts the process, so a test that triggers one fails. Leak checking is on (LSan).
#
# Every executable also gets tests/sanitizers/sanitizer_defaults.cpp, which compiles in the default
# ASAN/LSAN/UBSAN options and the leak suppressions of tests/sanitizers/lsan.supp (third-party
# leaks only). The environment (ASAN_OPTIONS, LSAN_OPTIONS, UBSAN_OPTIONS) still overrides them.

#
# WRAP_FUZZ: the same sanitizers plus libFuzzer's coverage instrumentation, for the fuzz targets of
# tests/fuzz (clang only; scripts/fuzz.sh configures it). Only the loaders and the fuzzers are built
# in such a build: clang-14 lacks the C++23 library support of the rest (see tests/fuzz/compat).

option(WRAP_SANITIZE "Build everything with AddressSanitizer + UndefinedBehaviorSanitizer" OFF)
option(WRAP_FUZZ "Build the libFuzzer targets of tests/fuzz (clang; ASan + UBSan)" OFF)

if(WRAP_SANITIZE AND WRAP_FUZZ)
  message(FATAL_ERROR "WRAP_SANITIZE and WRAP_FUZZ are separate builds: choose one")
endif()

if(WRAP_SANITIZE OR WRAP_FUZZ)
  set(_wrap_san_flags -fsanitize=address,undefined -fno-sanitize-recover=all
      -fno-omit-frame-pointer)
  if(WRAP_FUZZ)
    if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
      message(FATAL_ERROR "WRAP_FUZZ needs clang (libFuzzer): configure with "
                          "-DCMAKE_CXX_COMPILER=clang++-14, as scripts/fuzz.sh does")
    endif()
    list(APPEND _wrap_san_flags -fsanitize=fuzzer-no-link)
    # clang-14 with libstdc++ 12 has no std::expected or std::source_location: tests/fuzz/compat
    # stands in for them.
    include_directories(BEFORE ${CMAKE_CURRENT_LIST_DIR}/../tests/fuzz/compat)
  endif()
  add_compile_options(${_wrap_san_flags})
  add_link_options(-fsanitize=address,undefined)
  message(STATUS "Sanitizers: building with ${_wrap_san_flags}")

  # The suppressions file becomes a string literal in a generated source file.
  set(_wrap_supp ${CMAKE_CURRENT_LIST_DIR}/../tests/sanitizers/lsan.supp)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_wrap_supp})
  file(READ ${_wrap_supp} WRAP_LSAN_SUPPRESSIONS)
  set(WRAP_SANITIZER_DEFAULTS_CPP ${CMAKE_BINARY_DIR}/wrap_sanitizer_defaults.cpp)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/../tests/sanitizers/sanitizer_defaults.cpp.in
                 ${WRAP_SANITIZER_DEFAULTS_CPP} @ONLY)
endif()

# wrap_sanitizer_defaults_for_executables(DIR): adds the compiled-in sanitizer defaults to every
# executable defined in DIR and below. Call once, at the end of the top-level CMakeLists.txt.
function(wrap_sanitizer_defaults_for_executables dir)
  if(NOT WRAP_SANITIZE AND NOT WRAP_FUZZ)
    return()
  endif()
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(t IN LISTS targets)
    get_target_property(type ${t} TYPE)
    if(type STREQUAL "EXECUTABLE")
      target_sources(${t} PRIVATE ${WRAP_SANITIZER_DEFAULTS_CPP})
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(d IN LISTS subdirs)
    wrap_sanitizer_defaults_for_executables(${d})
  endforeach()
endfunction()
