#!/usr/bin/env bash
# Installs everything airtwin needs to build, test and run, from Debian 12's archive.
# Idempotent: packages already present are left alone. Run as root (or with sudo).
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake pkg-config git clang-format
  # physics twin: MuJoCo 2.2 (its CMake config needs qhull headers and OpenGL)
  libmujoco-dev libqhull-dev libgl-dev
  # offscreen rendering
  libosmesa6-dev
  # numerics: Eigen (incl. its Levenberg-Marquardt), SUNDIALS CVODE
  libeigen3-dev libsundials-dev
  # vision, images and video (ffmpeg backs cv::VideoWriter)
  libopencv-dev ffmpeg
  # command line, data files, logging
  libcli11-dev nlohmann-json3-dev libyaml-cpp-dev libspdlog-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
)

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
