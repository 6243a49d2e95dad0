#!/usr/bin/env bash
# Fuzzes the loaders with libFuzzer (clang-14, AddressSanitizer + UndefinedBehaviorSanitizer):
#   scripts/fuzz.sh [SECONDS] [TARGET...]
# TARGET: project_json mesh_stl mesh_obj mesh_ply step urdf (default: all), SECONDS per target
# (default 60). FUZZ_BUILD_DIR (default build-fuzz) may be set.
#
# Installs the project's packages plus clang-14 and libclang-rt-14-dev when missing, configures
# FUZZ_BUILD_DIR with -DWRAP_FUZZ=ON, builds the fuzzers and runs each one for SECONDS on its
# corpus: FUZZ_BUILD_DIR/corpus/TARGET (grows as the fuzzer finds new inputs), read together with
# tests/fuzz/seeds/TARGET, tests/fuzz/regressions/TARGET and the example projects and meshes.
# Findings (crash-*, leak-*, timeout-*, oom-*) go to FUZZ_BUILD_DIR/findings/TARGET/; the script
# exits 1 when there are any. Once fixed, copy the finding into tests/fuzz/regressions/TARGET/:
# the normal test suite replays it (fuzz_replay_test). A STEP finding that crashes inside
# OpenCASCADE (not in Wrap's frames) goes to tests/fuzz/regressions/step_crashes_occt/, where the
# replay checks that `wrap`'s child-process import turns it into an error.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-60}
shift || true
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(project_json mesh_stl mesh_obj mesh_ply step urdf)
BUILD=${FUZZ_BUILD_DIR:-build-fuzz}

bash scripts/install_deps.sh
fuzz_packages=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${fuzz_packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
if [[ ${#missing[@]} -gt 0 ]]; then
  SUDO=""
  [[ $(id -u) -eq 0 ]] || SUDO="sudo"
  echo "fuzz: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
    "${missing[@]}"
fi

cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++-14 -DWRAP_FUZZ=ON -DWRAP_BUILD_UI=OFF >/dev/null
cmake --build "$BUILD" --target "${targets[@]/#/fuzz_}" --parallel "$(nproc)"

# Extra read-only corpus folders per target: the example projects and their meshes.
extra_dirs() {
  case "$1" in
    project_json) echo projects ;;
    mesh_stl) echo assets/parts/stool ;;
    mesh_obj) echo assets/parts/chair assets/parts/cross assets/parts/cube ;;
    step) echo assets/parts/step ;;
    *) ;;
  esac
}

found=0
for t in "${targets[@]}"; do
  corpus="$BUILD/corpus/$t"
  findings="$BUILD/findings/$t"
  mkdir -p "$corpus" "$findings" "tests/fuzz/regressions/$t"
  echo "fuzz: $t for ${seconds}s"
  # OpenCASCADE crashes on some damaged STEP files (wrap survives them: it imports STEP in a child
  # process); libFuzzer's fork mode keeps fuzzing past them and saves each one.
  fork_mode=()
  [[ "$t" != step ]] || fork_mode=(-fork=1 -ignore_crashes=1)
  # shellcheck disable=SC2046
  "$BUILD/tests/fuzz/fuzz_$t" "${fork_mode[@]}" -max_total_time="$seconds" -timeout=20 \
    -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 -artifact_prefix="$findings/" \
    "$corpus" "tests/fuzz/seeds/$t" "tests/fuzz/regressions/$t" $(extra_dirs "$t") \
    >"$BUILD/fuzz_$t.log" 2>&1 || true
  grep -E "^(#[0-9]+ +DONE|stat::number_of_executed_units|stat::peak_rss_mb)" \
    "$BUILD/fuzz_$t.log" || tail -n 5 "$BUILD/fuzz_$t.log"
  if compgen -G "$findings/*" >/dev/null; then
    echo "fuzz: $t: FINDINGS in $findings (log: $BUILD/fuzz_$t.log):"
    ls "$findings"
    found=1
  fi
done
exit "$found"
