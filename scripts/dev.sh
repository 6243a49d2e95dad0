#!/usr/bin/env bash
# The README's commands: install the dependencies, build, then run the demo or the tests.
#   scripts/dev.sh demo   install, build `wrap` (not the tests), and run the main job on the
#                         built-in stool example: validate, describe, plan (validated) and
#                         render the plan's keyframes and the goal into out/stool/
#   scripts/dev.sh test   install, build, and run the whole test suite (what CI runs)
#   scripts/dev.sh build  install and build only
#   scripts/dev.sh sanitize     install, build everything with ASan + UBSan (-DWRAP_SANITIZE=ON)
#                               into build-asan and run the whole test suite there
#   scripts/dev.sh soak   install, build, and plan every example project 50 times in one process
#                         (the load tests with WRAP_SOAK_ROUNDS=50; about 25 CPU minutes)
#   scripts/dev.sh cluster-test install (with Slurm and munge), build `wrap`, and run the Slurm
#                               test (scripts/slurm/cluster_test.sh: a single-node Slurm of its
#                               own runs a small suite as a job array, a shard is cancelled and
#                               resumed, the merge is checked; as root; about 1-3 minutes)
#   scripts/dev.sh sanitize-ci  the part of `sanitize` that CI runs: no UI, only the suites in
#                               SANITIZE_CI_SUITES below (core, model, geometry, robot,
#                               collision with URDF import, the fuzz regression and seed replay)
# BUILD_DIR (default: build), SANITIZE_BUILD_DIR (default: build-asan) and BUILD_TYPE (default:
# RelWithDebInfo) may be set.
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-demo}
BUILD_TYPE=${BUILD_TYPE:-RelWithDebInfo}

# The suites (test binaries, ctest labels) of `sanitize-ci`: the loaders (project JSON, meshes,
# URDF: model, geometry, robot and collision with the URDF importer, and the fuzz corpus replay),
# which build without the wrench, planner, motion, sim or UI libraries. The other suites (wrench,
# task, motion, sim, app and reliability, render, GUI) run under sanitizers only in `sanitize`:
# building the whole engine with ASan does not fit CI's time budget next to the normal build.
SANITIZE_CI_SUITES=(core_test model_test geometry_test robot_test robot_no_alloc_test
  collision_test fuzz_replay_test)

if [[ "$mode" == cluster-test ]]; then
  bash scripts/install_deps.sh --cluster
  BUILD_DIR=${BUILD_DIR:-build}
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE"
  cmake --build "$BUILD_DIR" --parallel "$(nproc)" --target wrap
  exec bash scripts/slurm/cluster_test.sh "$BUILD_DIR/app/wrap"
fi

bash scripts/install_deps.sh
case "$mode" in
  sanitize | sanitize-ci)
    BUILD_DIR=${SANITIZE_BUILD_DIR:-build-asan}
    ui=ON
    [[ "$mode" == sanitize ]] || ui=OFF
    cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE" -DWRAP_SANITIZE=ON \
      -DWRAP_BUILD_UI="$ui"
    if [[ "$mode" == sanitize ]]; then
      cmake --build "$BUILD_DIR" --parallel "$(nproc)"
      ctest --test-dir "$BUILD_DIR" --output-on-failure --parallel "$(nproc)"
    else
      cmake --build "$BUILD_DIR" --parallel "$(nproc)" --target "${SANITIZE_CI_SUITES[@]}"
      labels=$(IFS='|'; echo "${SANITIZE_CI_SUITES[*]}")
      ctest --test-dir "$BUILD_DIR" --output-on-failure --parallel "$(nproc)" -L "^($labels)\$"
    fi
    exit 0
    ;;
esac

BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE"
if [[ "$mode" == demo ]]; then
  # The demo needs the command line only: the tests, benchmarks and GUI are built by `test`.
  cmake --build "$BUILD_DIR" --parallel "$(nproc)" --target wrap
else
  cmake --build "$BUILD_DIR" --parallel "$(nproc)"
fi

case "$mode" in
  build) ;;
  demo)
    "$BUILD_DIR/app/wrap" validate projects/stool.json
    "$BUILD_DIR/app/wrap" info projects/stool.json
    mkdir -p out/stool
    "$BUILD_DIR/app/wrap" preprocess projects/stool.json -o out/stool/preprocess.json
    "$BUILD_DIR/app/wrap" plan projects/stool.json -o out/stool/plan.json --validate
    "$BUILD_DIR/app/wrap" render projects/stool.json -o out/stool/plan --plan out/stool/plan.json
    "$BUILD_DIR/app/wrap" render projects/stool.json -o out/stool/motion --plan out/stool/plan.json --frames 12
    "$BUILD_DIR/app/wrap" render projects/stool.json -o out/stool --explode 0.4
    ;;
  test)
    ctest --test-dir "$BUILD_DIR" --output-on-failure --parallel "$(nproc)"
    ;;
  soak)
    WRAP_SOAK_ROUNDS=${WRAP_SOAK_ROUNDS:-50} "$BUILD_DIR/tests/load/load_test" \
      --gtest_filter='Load.*Planned*'
    ;;
  *)
    echo "usage: scripts/dev.sh [demo|test|build|soak|sanitize|sanitize-ci|cluster-test]" >&2
    exit 2
    ;;
esac
