#!/usr/bin/env bash
# Installs the Debian 12 packages LiverSim needs to build and test, only those missing.
# Usage: packaging/setup-debian.sh [--measuring]   (packaging/liversim.sh calls it before building)
# --measuring: also what packaging/regenerate-docs.sh measures with (valgrind's instruction
# counts, LLVM's coverage tools, the sqlite3 shell of the soak's report).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache
  clang libclang-rt-14-dev
  qt6-base-dev qt6-charts-dev libqt6opengl6-dev qt6-tools-dev qt6-tools-dev-tools qt6-l10n-tools
  libqt6sql6-sqlite libgl-dev libgl1-mesa-dri
  libvtk9-dev libeigen3-dev libassimp-dev libgmsh-dev libsqlite3-dev libx11-dev libsodium-dev
  libpq-dev postgresql openssl
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev python3 python3-jsonschema graphviz
  xvfb xauth
  libqt6svg6 qt6-translations-l10n fonts-wqy-microhei desktop-file-utils appstream
)
case ${1:-} in
  --measuring) packages+=(valgrind llvm-14 sqlite3) ;;
  "") ;;
  *)
    echo "usage: $0 [--measuring]" >&2
    exit 2
    ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "liversim setup: installing ${#missing[@]} missing Debian packages: ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "liversim setup: need root or sudo to install packages" >&2; exit 1; }
    sudo_cmd=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
