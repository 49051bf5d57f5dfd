#!/usr/bin/env bash
# Installs the Debian packages bvhlab needs, and only the missing ones.
# As root: `apt-get update` once, then `apt-get install -y` of exactly those.
# Otherwise: prints the command to run and fails, so `make` stops.
set -euo pipefail
packages=(build-essential cmake ninja-build libcgal-dev libgmp-dev libmpfr-dev libeigen3-dev libassimp-dev
          libbenchmark-dev libgtest-dev libfcl-dev libcli11-dev nlohmann-json3-dev libfmt-dev
          python3 python3-matplotlib ca-certificates)
# matplotlib's python3-fonttools needs python3-scipy or python3-munkres: apt takes the first, which brings
# Pythran and 16 MB more to fetch. Naming munkres (12 kB) leaves SciPy out: the packages' install took 53
# instead of 59 s (medians of three, tests/README.md "Build and CI times").
packages+=(python3-munkres)
# Used by the fetch of larger meshes (npm pack) and by the fuzzers (clang, its sanitizer runtimes).
packages+=(clang libclang-rt-14-dev)
# `make format-check` (the first stage of .ci/run).
packages+=(clang-format)
# The Python module (python/) and its tests: headers, pybind11, numpy, pytest.
packages+=(python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest)
# npm is needed as a command, from whatever package provides it: some machines carry a nodejs build that
# bundles npm and conflicts with Debian's npm package, so that package is asked for only when no npm exists.
command -v npm >/dev/null 2>&1 || packages+=(npm)
if [ -n "${BVHLAB_EXTRA_PACKAGES:-}" ]; then read -r -a extra <<<"$BVHLAB_EXTRA_PACKAGES"; packages+=("${extra[@]}"); fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "bvhlab: missing Debian packages: ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "bvhlab: run as root:  apt-get update && apt-get install -y ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends "${missing[@]}"
