#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Shared by run.sh and test.sh: install the Debian packages if any is missing (needs root:
# apt-get install), then configure and build into build/. With --fuzz (test.sh): also clang
# and libFuzzer, and the fuzz targets (fuzz/, ASan + UBSan) built with them into build-fuzz/.
# The list is everything a bare Debian 12 lacks for the build and the tests: the compiler and a
# build program (make, which CMake's default generator drives), the libraries, gmsh for the
# meshes, openmpi-bin for mpirun (ContinuumMpi.MatchesSerial runs the static solve on 2 ranks),
# and Python with matplotlib, pandas, h5py and pytest for the plots and their tests (python/).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
packages=(g++ make cmake pkg-config libeigen3-dev petsc-dev openmpi-bin libcgal-dev
          libgmsh-dev gmsh libhdf5-dev libgtest-dev libyaml-cpp-dev nlohmann-json3-dev
          python3 python3-matplotlib python3-numpy python3-pandas python3-h5py python3-pytest)
fuzz=false
if [[ ${1:-} == --fuzz ]]; then
  fuzz=true
  packages+=(clang-14 libclang-rt-14-dev libfuzzer-14-dev)  # compiler-rt: the sanitizers and libFuzzer runtimes
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing Debian packages: ${missing[*]}"
  if [[ $(id -u) -ne 0 ]]; then
    echo "setup: installing packages needs root (apt-get install); run as root or install: ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  log=$(mktemp)
  # A failed install stops here: CMake never runs on a half-installed toolchain. apt's own
  # output is kept in the log and its last lines shown, since they say why.
  if ! { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
    tail -n 5 "$log" >&2
    echo "setup: apt-get could not install: ${missing[*]} (full apt output: $log)" >&2
    exit 1
  fi
  rm -f "$log"
fi
jobs=$(nproc)
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" -j "$jobs"
if $fuzz; then
  # The fuzz build needs no OpenMP (one thread per input), tests or benchmarks.
  CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$root/build-fuzz" -DCMAKE_BUILD_TYPE=Release -DARLEQUIN_FUZZ=ON \
    -DARLEQUIN_WITH_OPENMP=OFF -DARLEQUIN_BUILD_TESTS=OFF -DARLEQUIN_BUILD_BENCH=OFF >/dev/null
  cmake --build "$root/build-fuzz" -j "$jobs"
fi
