#!/usr/bin/env bash
# Installs exactly the Debian 12 packages Wrap builds and tests with. Idempotent: when every
# package is already installed it returns at once without touching apt.
#   scripts/install_deps.sh            what the build and the test suite need
#   scripts/install_deps.sh --cluster  also Slurm and munge, for `scripts/dev.sh cluster-test`
#                                      (which starts its own daemons; on a machine with systemd,
#                                      Debian also enables their services, which the test does
#                                      not use)
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config
  # engine: math, mesh import, project files, command line
  libeigen3-dev libassimp-dev nlohmann-json3-dev libcli11-dev
  # STEP import: OpenCASCADE 7.6 (data exchange, modelling, OCAF/XCAF; WRAP_WITH_OCCT)
  libocct-data-exchange-dev libocct-modeling-algorithms-dev libocct-modeling-data-dev
  libocct-foundation-dev libocct-ocaf-dev
  # preprocessing: convex hulls (qhull), parallel grasp sampling (oneTBB)
  libqhull-dev libtbb-dev
  # robots: collision (FCL + libccd), URDF import
  libfcl-dev libccd-dev liburdfdom-dev
  # motion planning: OMPL (its library links against these Boost components)
  libompl-dev libboost-serialization-dev libboost-filesystem-dev libboost-system-dev
  # wrench LP: Clp (the reference LP solver behind the dense simplex)
  coinor-libclp-dev
  # sim: MuJoCo (its CMake config also wants libgl-dev and libqhull-dev, listed elsewhere here)
  libmujoco-dev
  # ui: GL, offscreen contexts (EGL, OSMesa), PNG (stb), window and widgets
  libstb-dev
  libgl-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libosmesa6-dev libglfw3-dev libimgui-dev
  # tests and benchmarks
  libgtest-dev libbenchmark-dev
  # GUI tests: a virtual X server for the window (xvfb-run needs xauth)
  xvfb xauth
)

if [[ "${1:-}" == --cluster ]]; then
  # cluster test: a single-node Slurm (controller, node daemon, sbatch) and its authentication
  PACKAGES+=(slurm-wlm munge)
elif [[ $# -gt 0 ]]; then
  echo "usage: scripts/install_deps.sh [--cluster]" >&2
  exit 2
fi

missing=()
for p in "${PACKAGES[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install_deps: run as root (or install sudo)" >&2; exit 2; }
  SUDO="sudo"
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
