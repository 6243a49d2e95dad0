#!/usr/bin/env bash
# The README's commands: install the dependencies, build, then run the demo or the tests.
#   scripts/dev.sh demo   install, build, and run the main job on the built-in stool example:
#                         validate, describe, plan (validated) and render the plan's keyframes
#                         and the goal into out/stool/
#   scripts/dev.sh test   install, build, and run the whole test suite (what CI runs)
#   scripts/dev.sh build  install and build only
# BUILD_DIR (default: build) and BUILD_TYPE (default: RelWithDebInfo) may be set.
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-demo}
BUILD_DIR=${BUILD_DIR:-build}
BUILD_TYPE=${BUILD_TYPE:-RelWithDebInfo}

bash scripts/install_deps.sh
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE"
cmake --build "$BUILD_DIR" --parallel "$(nproc)"

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
  *)
    echo "usage: scripts/dev.sh [demo|test|build]" >&2
    exit 2
    ;;
esac
