#!/usr/bin/env bash
# Installs the Debian 12 packages trivcon builds and tests with (as root; uses sudo otherwise).
# Shared by scripts/demo.sh, scripts/test.sh and scripts/bench.sh.
set -euo pipefail
packages=(build-essential cmake pkg-config zlib1g-dev libeigen3-dev libsuitesparse-dev libopenblas-dev libmetis-dev
          libcli11-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev libstb-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
