#!/usr/bin/env bash
# Installs the Debian 12 packages ceres_sesync needs. Idempotent; quiet when all
# are present. Run as root (or with sudo available).
set -euo pipefail
packages=(
  build-essential cmake clang clang-format
  libceres-dev libeigen3-dev libsuitesparse-dev libgoogle-glog-dev
  libgflags-dev libgtest-dev libgmock-dev libspectra-dev
  gnuplot-nox python3-matplotlib time
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
    missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "install-deps: installing ${missing[*]}" >&2
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
