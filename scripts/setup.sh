#!/usr/bin/env bash
# Installs everything airtwin needs to build, test and run, from Debian 12's archive.
# Idempotent: packages already present are left alone. Run as root (or with sudo).
# Usage: bash scripts/setup.sh [--cfd]
#   --cfd  also installs OpenFOAM (Debian's openfoam, v1912) and the Python used to post-process
#          its results, for scripts/cfd/ (docs/cfd.md). The default set-up stays without it.
set -euo pipefail

cfd=0
for arg in "$@"; do
  case "$arg" in
    --cfd) cfd=1 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown argument '$arg' (expected --cfd or --help)" >&2; exit 2 ;;
  esac
done

packages=(
  # toolchain (ccache: scripts/test.sh uses it when present)
  build-essential cmake pkg-config git clang-format ccache
  # physics twin: MuJoCo 2.2 (its CMake config needs qhull headers and OpenGL)
  libmujoco-dev libqhull-dev libgl-dev
  # offscreen rendering
  libosmesa6-dev
  # the live viewer (airtwin view, docs/viewer.md): GLFW, Mesa's GLX and its software driver,
  # Xvfb, the X server its test draws on, and xdotool, which types and drags in it (XTest)
  libglfw3-dev libglx-mesa0 libgl1-mesa-dri xvfb xdotool
  # numerics: Eigen (incl. its Levenberg-Marquardt), SUNDIALS CVODE
  libeigen3-dev libsundials-dev
  # vision, images and video (ffmpeg backs cv::VideoWriter)
  libopencv-dev ffmpeg
  # command line, data files, logging
  libcli11-dev nlohmann-json3-dev libyaml-cpp-dev libspdlog-dev
  # tests and benchmarks; clang with its runtime libraries for libFuzzer (scripts/fuzz.sh: the
  # test stage's fuzz smoke; LLVM itself already comes with clang-format); libcsv, which
  # bench/library_bench.cc sets beside our CSV reader (docs/decisions.md)
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev libcsv-dev
  # the Python module (python/, docs/python.md): pybind11, Python's headers, numpy; its tests
  # run under pytest
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest
)
if [ "$cfd" = 1 ]; then
  # CFD of the jet: OpenFOAM (with Open MPI) and Debian's Python with numpy for post-processing
  packages+=(openfoam python3 python3-numpy python3-matplotlib)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get -o DPkg::Lock::Timeout=300 update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends -o DPkg::Lock::Timeout=300 "${missing[@]}"
echo "setup: done"
