#!/usr/bin/env bash
# Installs the Debian 12 packages sunvo needs. Idempotent: packages already present are skipped.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libopencv-dev libceres-dev libgeographiclib-dev
  libgpiod-dev libyaml-cpp-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-ephem povray
)
# node-mavlink (npm) decodes our MAVLink stream in the tests; installed only when node/npm is missing.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then PACKAGES+=(nodejs npm); fi
# --train: also the optional Sun-CNN training tools (large; CI only runs OpenCV DNN inference).
# --sanitize: clang-14 and its libFuzzer runtime for the fuzz harnesses (scripts/fuzz.sh).
for arg in "$@"; do
  case "$arg" in
    --train) PACKAGES+=(python3-torch python3-opencv) ;;
    --sanitize) PACKAGES+=(clang-14 libclang-rt-14-dev) ;;
    *) echo "usage: $0 [--train] [--sanitize]" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
# One line per step; the package manager's own output only when a step fails.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
step() {
  local what=$1
  shift
  echo "setup: $what"
  if ! "$@" >"$log" 2>&1; then
    echo "setup: FAILED: $what ($*):" >&2
    cat "$log" >&2
    exit 1
  fi
}
step "updating the package lists" $SUDO apt-get update -q
step "installing ${#missing[@]} packages: ${missing[*]}" \
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "setup: done"
