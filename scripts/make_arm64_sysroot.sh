#!/usr/bin/env bash
# Builds an arm64 (aarch64) Debian 12 sysroot holding every library sunvo links, for
# toolchains/aarch64-linux-gnu.cmake (SUNVO_SYSROOT) and for qemu-aarch64 -L.
#
#   scripts/make_arm64_sysroot.sh [SYSROOT]        (default: build/sysroot-arm64)
#
# Nothing arm64 is installed into the host: the script adds the arm64 architecture to dpkg (so
# apt can see arm64 package lists), resolves the -dev packages' Depends/Pre-Depends recursively
# for arm64, downloads the .debs into SYSROOT.debs/ with `apt-get download` and unpacks them with
# `dpkg -x`. Maintainer scripts do not run, so the script does by hand what they would do for a
# linker: absolute symlinks are made relative to the sysroot and the BLAS/LAPACK alternatives are
# linked. Host tools (crossbuild-essential-arm64, qemu-user) are installed with apt-get if missing.
# Idempotent: downloaded and unpacked packages are skipped on a second run.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SYSROOT="${1:-${ROOT}/build/sysroot-arm64}"
mkdir -p "${SYSROOT}"
SYSROOT="$(cd "${SYSROOT}" && pwd)"
DEBS="${SYSROOT}.debs"
mkdir -p "${DEBS}"

# The target libraries sunvo links (see scripts/setup.sh; benchmarks are off when cross-building).
DEV_PACKAGES=(
  libc6-dev libstdc++-12-dev
  libeigen3-dev libopencv-dev libceres-dev libgeographiclib-dev
  libyaml-cpp-dev libcli11-dev libgpiod-dev libgtest-dev libgmock-dev
)
HOST_TOOLS=(crossbuild-essential-arm64 qemu-user)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive

# --- host tools and the arm64 package lists --------------------------------------------------
need_update=0
if ! dpkg --print-foreign-architectures | grep -qx arm64; then
  echo "sysroot: adding dpkg architecture arm64 (package lists only; nothing arm64 is installed)"
  $SUDO dpkg --add-architecture arm64
  need_update=1
fi
if ! apt-cache show libc6:arm64 >/dev/null 2>&1; then need_update=1; fi
missing=()
for p in "${HOST_TOOLS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ "${need_update}" -eq 1 ] || [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "sysroot: installing host tools ${missing[*]}"
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# --- package closure -------------------------------------------------------------------------
# apt-cache depends --recurse lists every alternative of an "a | b" dependency (a superset, which
# is fine for a sysroot). Lines with ":arm64" are arm64 packages; names without a suffix are either
# Architecture: all packages (headers such as Eigen, data) or the host's copy of a Multi-Arch:
# foreign package (whose arm64 copy is in the list too); only the former are kept. Virtual
# packages ("<name>") are dropped.
# An Architecture: all package (CLI11, Eigen: headers only) has no ":arm64" name; asked for as one,
# apt-cache lists it as a missing virtual package and the closure silently lacks it.
targets=()
for p in "${DEV_PACKAGES[@]}"; do
  # (The listing is read whole: grep -q would exit early and fail the pipe under pipefail.)
  if grep -qx 'Architecture: all' <<<"$(apt-cache show --no-all-versions "${p}")"; then
    targets+=("${p}")
  else
    targets+=("${p}:arm64")
  fi
done
closure="$(apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
  --no-replaces --no-enhances "${targets[@]}" | grep -E '^[a-z0-9]' | sort -u)"
arm64_pkgs=$(grep -E ':arm64$' <<<"${closure}" || true)
plain=$(grep -vE ':' <<<"${closure}" || true)
all_pkgs=""
if [ -n "${plain}" ]; then
  # shellcheck disable=SC2086
  all_pkgs=$(apt-cache show --no-all-versions ${plain} |
    awk '/^Package:/{p=$2} /^Architecture: all$/{print p}' | sort -u)
fi
# shellcheck disable=SC2206
packages=(${arm64_pkgs} ${all_pkgs})
echo "sysroot: ${#packages[@]} packages in the closure of ${DEV_PACKAGES[*]}"

# --- download (only the .debs not yet in DEBS) ------------------------------------------------
# --print-uris names each package's file without downloading it.
uris="$(cd "${DEBS}" && apt-get download --print-uris "${packages[@]}")"
to_get=()
while read -r _uri file _size _hash; do
  [ -z "${file}" ] && continue
  [ -s "${DEBS}/${file}" ] && continue
  # file is name_version_arch.deb (version with ':' written as %3a).
  name="${file%%_*}"
  arch="${file##*_}"
  arch="${arch%.deb}"
  if [ "${arch}" = "all" ]; then to_get+=("${name}"); else to_get+=("${name}:${arch}"); fi
done <<<"${uris}"
if [ ${#to_get[@]} -gt 0 ]; then
  echo "sysroot: downloading ${#to_get[@]} packages into ${DEBS}"
  (cd "${DEBS}" && apt-get download -qq "${to_get[@]}")
fi

# --- unpack (a stamp per .deb) ----------------------------------------------------------------
stamps="${SYSROOT}/.sunvo-unpacked"
mkdir -p "${stamps}"
unpacked=0
for deb in "${DEBS}"/*.deb; do
  stamp="${stamps}/$(basename "${deb}").done"
  [ -e "${stamp}" ] && continue
  dpkg -x "${deb}" "${SYSROOT}"
  : >"${stamp}"
  unpacked=$((unpacked + 1))
done
echo "sysroot: unpacked ${unpacked} new packages"

# --- absolute symlinks -> relative ------------------------------------------------------------
# A link /usr/lib/aarch64-linux-gnu/libfoo.so -> /lib/aarch64-linux-gnu/libfoo.so.1 would point
# into the host; rewrite it to the same path inside the sysroot, relative to the link's folder.
fixed=0
while IFS= read -r -d '' link; do
  target="$(readlink "${link}")"
  case "${target}" in
    /*)
      rel="$(realpath -m -s --relative-to="$(dirname "${link}")" "${SYSROOT}${target}")"
      ln -sfn "${rel}" "${link}"
      fixed=$((fixed + 1))
      ;;
  esac
done < <(find "${SYSROOT}" -path "${stamps}" -prune -o -type l -print0)
echo "sysroot: made ${fixed} absolute symlinks relative"

# --- alternatives the maintainer scripts would have set up -----------------------------------
# libblas3/liblapack3/libatlas3-base put their libraries under blas/, lapack/ and atlas/ and rely
# on update-alternatives for the names the linker and the loader look for. ATLAS is preferred when
# present, as on the x86-64 hosts (Debian's priorities: ATLAS 35 over the reference 10).
multiarch="${SYSROOT}/usr/lib/aarch64-linux-gnu"
for lib in blas lapack; do
  for so in "lib${lib}.so.3" "lib${lib}.so"; do
    for provider in atlas "${lib}"; do
      if [ -e "${multiarch}/${provider}/${so}" ]; then
        ln -sfn "${provider}/${so}" "${multiarch}/${so}"
        break
      fi
    done
  done
done

# --- CMake package files ----------------------------------------------------------------------
# Ceres' exported targets name LAPACK/BLAS by absolute path (/usr/lib/aarch64-linux-gnu/...),
# which a cross build would look for on the host. Prefix them with ${CMAKE_SYSROOT}, which is
# empty in a native build on the target, so the files stay valid there. Only paths following
# '"' or ';' are rewritten, so a second run changes nothing.
while IFS= read -r -d '' f; do
  if grep -qE '[";]/usr/lib/aarch64-linux-gnu/' "${f}"; then
    # shellcheck disable=SC2016  # ${CMAKE_SYSROOT} is literal text for CMake, not for the shell
    sed -i -E 's#([";])/usr/lib/aarch64-linux-gnu/#\1${CMAKE_SYSROOT}/usr/lib/aarch64-linux-gnu/#g' "${f}"
    echo "sysroot: prefixed absolute library paths with \${CMAKE_SYSROOT} in ${f#"${SYSROOT}"/}"
  fi
done < <(find "${SYSROOT}/usr/lib/aarch64-linux-gnu/cmake" "${SYSROOT}/usr/lib/cmake" \
  "${SYSROOT}/usr/share" -name '*Targets*.cmake' -print0 2>/dev/null)

# --- check ------------------------------------------------------------------------------------
for f in usr/include/eigen3/Eigen/Core usr/lib/aarch64-linux-gnu/cmake/opencv4/OpenCVConfig.cmake \
  usr/lib/aarch64-linux-gnu/cmake/Ceres/CeresConfig.cmake \
  usr/lib/aarch64-linux-gnu/cmake/yaml-cpp/yaml-cpp-config.cmake \
  usr/include/GeographicLib/LocalCartesian.hpp usr/lib/aarch64-linux-gnu/libGeographicLib.so \
  usr/lib/aarch64-linux-gnu/libgpiod.so lib/ld-linux-aarch64.so.1 \
  usr/lib/aarch64-linux-gnu/libblas.so.3 usr/lib/aarch64-linux-gnu/liblapack.so.3; do
  if [ ! -e "${SYSROOT}/${f}" ]; then
    echo "sysroot: missing ${SYSROOT}/${f}" >&2
    exit 1
  fi
done
echo "sysroot: ready at ${SYSROOT} ($(du -sh "${SYSROOT}" | cut -f1); .debs $(du -sh "${DEBS}" | cut -f1))"
