#!/usr/bin/env bash
# Checks a sunvo .deb made by `cpack` (cmake/SunvoPackaging.cmake) and prints its size.
#
#   scripts/check_deb.sh DEB ARCH BUILD_DIR [SYSROOT]
#
# ARCH: the Debian architecture the package must have (arm64, amd64). BUILD_DIR: the build folder
# cpack ran in (sunvo_rover and /etc/sunvo/rover.yaml are required exactly when that build made
# sunvo_rover). SYSROOT: for a foreign ARCH, the sysroot of scripts/make_arm64_sysroot.sh, whose
# .debs (SYSROOT.debs) say which package holds each library; for the host's ARCH the host's dpkg
# database says it.
#
# Checks, each failing the script:
#  1. control: Package sunvo, Architecture ARCH, maintainer scripts present and executable and
#     valid sh (shellcheck when installed), conffiles = exactly the files under /etc;
#  2. contents: the programs, the unit, the udev rules, the guide; every program an ELF for ARCH;
#  3. Depends: the packages holding the libraries the programs link directly (readelf NEEDED,
#     resolved through the sysroot's or host's library folders, symlinks and alternatives
#     followed) plus adduser must equal the Depends names, and each version bound must hold for
#     the version in the sysroot (or on the host);
#  4. the systemd unit passes `systemd-analyze verify` with no warning (ExecStart pointed at the
#     extracted binary), or a key=value parse check where systemd-analyze is missing; its
#     ExecStart program and --config file are in the package;
#  5. the udev rules parse: every rule is comma-separated KEY[{attr}] OP "value" with a known key,
#     match operators on match keys and assignment operators on assignment keys;
#  6. every path in the installed config (/etc/sunvo/rover.yaml) is a file in the package, a
#     /dev name one of the udev rules' SYMLINK+= creates, or in a folder the unit has systemd make
#     (LogsDirectory=, StateDirectory=); none is relative; trigger.gpio_chip matches the KERNEL of
#     the rules' GPIO rule; a packaged ONNX model has the sha256 its model card (.json) states;
#  7. for the host's ARCH: every packaged program answers --help with exit 0 and "Usage:", and
#     --version with exit 0 and "<program> <the package's Version>" (firmware_app/cli).
set -euo pipefail

if [ $# -lt 3 ] || [ $# -gt 4 ]; then
  echo "usage: $0 DEB ARCH BUILD_DIR [SYSROOT]" >&2
  exit 2
fi
DEB="$1"
ARCH="$2"
BUILD_DIR="$3"
SYSROOT="${4:-}"
if [ -n "${SYSROOT}" ]; then SYSROOT="$(cd "${SYSROOT}" && pwd)"; fi
HOST_ARCH="$(dpkg --print-architecture)"
if [ "${ARCH}" != "${HOST_ARCH}" ] && [ -z "${SYSROOT}" ]; then
  echo "check_deb: ${ARCH} is not the host's architecture (${HOST_ARCH}): give the SYSROOT" >&2
  exit 2
fi

if [ ! -f "${DEB}" ]; then
  echo "check_deb: ${DEB}: no such file" >&2
  exit 1
fi
fail=0
bad() {
  echo "check_deb: FAIL: $*"
  fail=1
}
words() { tr '\n' ' ' <<<"$1"; }  # a list, one item a line, on one line
WORK="$(mktemp -d)"
trap 'rm -rf "${WORK}"' EXIT

# --- 1. control --------------------------------------------------------------------------------
field() { dpkg-deb -f "${DEB}" "$1"; }
[ "$(field Package)" = "sunvo" ] || bad "Package is '$(field Package)', not sunvo"
[ "$(field Architecture)" = "${ARCH}" ] || bad "Architecture is '$(field Architecture)', not ${ARCH}"
dpkg-deb -e "${DEB}" "${WORK}/control"
for script in postinst prerm postrm; do
  f="${WORK}/control/${script}"
  if [ ! -x "${f}" ]; then
    bad "maintainer script ${script} missing or not executable"
    continue
  fi
  sh -n "${f}" || bad "${script}: sh -n fails"
  if command -v shellcheck >/dev/null; then shellcheck -s sh "${f}" || bad "${script}: shellcheck"; fi
done
dpkg-deb -x "${DEB}" "${WORK}/root"
etc_files="$(cd "${WORK}/root" && find etc -type f 2>/dev/null | sed 's|^|/|' | sort)"
conffiles="$(sort "${WORK}/control/conffiles" 2>/dev/null || true)"
[ "${etc_files}" = "${conffiles}" ] ||
  bad "conffiles ($(words "${conffiles}")) differ from the files under /etc ($(words "${etc_files}"))"

# --- 2. contents -------------------------------------------------------------------------------
programs=(sunvo_replay sunvo_eval sunvo_sun sunvo_geodesy sunvo_kitti_replay sunvo_track_vo
  sunvo_pose_reader)
expected=(/lib/systemd/system/sunvo.service /etc/udev/rules.d/60-sunvo.rules
  /usr/share/doc/sunvo/deployment.md)
has_rover=0
if [ -n "$(find "${BUILD_DIR}" -type f -name sunvo_rover -perm -u+x -print -quit)" ]; then
  has_rover=1
  programs+=(sunvo_rover)
  expected+=(/etc/sunvo/rover.yaml)
fi
for p in "${programs[@]}"; do expected+=("/usr/bin/${p}"); done
for f in "${expected[@]}"; do
  [ -f "${WORK}/root${f}" ] || bad "${f} is not in the package"
done
case "${ARCH}" in
  arm64) machine="AArch64" ;;
  amd64) machine="Advanced Micro Devices X86-64" ;;
  *) machine="?" ;;
esac
for f in "${WORK}"/root/usr/bin/*; do
  m="$({ readelf -h "${f}" 2>/dev/null || true; } | sed -n 's/^ *Machine: *//p')"
  [ "${m}" = "${machine}" ] || bad "$(basename "${f}"): ELF machine '${m}', not ${ARCH}'s"
done

# --- 3. Depends --------------------------------------------------------------------------------
# Which package holds a path of the target's file system: for a foreign architecture, an index
# of the sysroot's .debs (path -> package, made once and kept next to them); else dpkg -S.
index=""
if [ "${ARCH}" != "${HOST_ARCH}" ]; then
  index="${SYSROOT}.debs/contents.index"
  if [ ! -s "${index}" ] || [ -n "$(find "${SYSROOT}.debs" -name '*.deb' -newer "${index}" -print -quit)" ]; then
    for d in "${SYSROOT}.debs"/*.deb; do
      pkg="$(dpkg-deb -f "${d}" Package)"
      dpkg-deb -c "${d}" | awk -v p="${pkg}" '{ sub(/^\.\//, "", $6); print $6, p }'
    done >"${index}.tmp"
    mv "${index}.tmp" "${index}"
  fi
fi
owner() {  # $1: path relative to the root, no leading slash
  if [ -n "${index}" ]; then
    awk -v f="$1" '$1 == f { print $2; exit }' "${index}"
  else
    { dpkg -S "/$1" 2>/dev/null || true; } | head -n 1 | cut -d: -f1
  fi
}
version_of() {
  if [ -n "${index}" ]; then
    d="$(find "${SYSROOT}.debs" -name "$1_*.deb" -print -quit)"
    if [ -n "${d}" ]; then dpkg-deb -f "${d}" Version; fi
  else
    dpkg-query -W -f='${Version}' "$1:${ARCH}" 2>/dev/null || dpkg-query -W -f='${Version}' "$1" 2>/dev/null || true
  fi
}
root="${SYSROOT:-/}"
multiarch="$(case "${ARCH}" in arm64) echo aarch64-linux-gnu ;; amd64) echo x86_64-linux-gnu ;; esac)"
needed="$(for f in "${WORK}"/root/usr/bin/*; do
  { readelf -d "${f}" 2>/dev/null || true; } | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'
done | sort -u)"
derived="adduser"
for so in ${needed}; do
  pkg=""
  for dir in "lib/${multiarch}" "usr/lib/${multiarch}" lib usr/lib; do
    [ -e "${root%/}/${dir}/${so}" ] || continue
    real="$(readlink -f "${root%/}/${dir}/${so}")"
    rel="${real#"${root%/}"/}"
    # The library's real file, else the name it was found under (dpkg knows /lib/... for
    # /usr/lib/... on a merged-/usr system and vice versa).
    for cand in "${rel}" "${rel#usr/}" "usr/${rel}" "${dir}/${so}"; do
      pkg="$(owner "${cand}")"
      [ -n "${pkg}" ] && break
    done
    [ -n "${pkg}" ] && break
  done
  if [ -z "${pkg}" ]; then
    bad "no package of ${ARCH} holds ${so} (NEEDED by the programs)"
    continue
  fi
  echo "check_deb: ${so} <- ${pkg}"
  derived="${derived}"$'\n'"${pkg}"
done
derived="$(sort -u <<<"${derived}")"
depends="$(field Depends)"
declared="$(tr ',' '\n' <<<"${depends}" | sed 's/^ *//; s/ *(.*//' | sort -u)"
[ "${derived}" = "${declared}" ] ||
  bad "Depends names ($(words "${declared}")) differ from the packages the programs need ($(words "${derived}"))"
while IFS= read -r dep; do
  name="$(sed 's/^ *//; s/ *(.*//' <<<"${dep}")"
  bound="$(sed -n 's/.*(\(.*\)).*/\1/p' <<<"${dep}")"
  [ -n "${bound}" ] || continue
  have="$(version_of "${name}")"
  if [ -z "${have}" ]; then
    bad "Depends ${dep}: ${name} is not available for ${ARCH}"
  elif ! dpkg --compare-versions "${have}" "${bound%% *}" "${bound#* }"; then
    bad "Depends ${dep}: ${ARCH} has ${name} ${have}"
  fi
done < <(tr ',' '\n' <<<"${depends}")

# --- 4. systemd unit ---------------------------------------------------------------------------
unit="${WORK}/root/lib/systemd/system/sunvo.service"
exec_start="$(sed -n 's/^ExecStart=//p' "${unit}")"
exec_bin="${exec_start%% *}"
config="$(sed -n 's/.*--config \([^ ]*\).*/\1/p' <<<"${exec_start}")"
if [ "${has_rover}" -eq 1 ]; then
  [ -x "${WORK}/root${exec_bin}" ] || bad "ExecStart program ${exec_bin} is not in the package"
  [ -f "${WORK}/root${config}" ] || bad "ExecStart config ${config} is not in the package"
fi
for key in Restart=on-failure RestartSec= LimitRTPRIO= LimitMEMLOCK=infinity User=sunvo Type=notify WatchdogSec= \
  "SupplementaryGroups=video gpio dialout"; do
  grep -q "^${key}" "${unit}" || bad "sunvo.service has no ${key}"
done
if command -v systemd-analyze >/dev/null; then
  # verify needs an executable ExecStart; point it at the packaged one (the binary need not run
  # here), or at /bin/true where the package has no sunvo_rover yet.
  target="${WORK}/root${exec_bin}"
  [ -x "${target}" ] || target=/bin/true
  mkdir -p "${WORK}/unit"
  sed "s#^ExecStart=${exec_bin}#ExecStart=${target}#" "${unit}" >"${WORK}/unit/sunvo.service"
  out="$(systemd-analyze verify "${WORK}/unit/sunvo.service" 2>&1)" || bad "systemd-analyze verify: ${out}"
  # Unknown keys and bad values are only warnings (exit 0); fail on any line about the unit.
  if grep -q "sunvo.service" <<<"${out}"; then bad "systemd-analyze verify: ${out}"; fi
  echo "check_deb: sunvo.service passes systemd-analyze verify"
else
  awk '/^[[:space:]]*(#|$)/ { next } /^\[(Unit|Service|Install)\]$/ { next }
       /^[A-Za-z]+=/ { next } { print "line " NR ": " $0; bad = 1 } END { exit bad }' "${unit}" ||
    bad "sunvo.service does not parse"
  echo "check_deb: systemd-analyze missing; sunvo.service parses as key=value"
fi

# --- 5. udev rules -----------------------------------------------------------------------------
rules="${WORK}/root/etc/udev/rules.d/60-sunvo.rules"
awk '
  /^[[:space:]]*(#|$)/ { next }
  {
    n = split($0, parts, /",[[:space:]]*/)
    for (i = 1; i <= n; ++i) {
      t = parts[i]; sub(/^[[:space:]]+/, "", t); if (i < n) t = t "\""
      if (!match(t, /^[A-Z_]+(\{[A-Za-z0-9_.]+\})?(==|!=|\+=|-=|:=|=)"[^"]*"$/)) {
        printf "line %d: bad token %s\n", NR, t; bad = 1; continue
      }
      key = t; sub(/[{=!+:-].*/, "", key)
      op = t; sub(/^[A-Z_]+(\{[A-Za-z0-9_.]+\})?/, "", op); sub(/".*/, "", op)
      is_match = key ~ /^(ACTION|DEVPATH|KERNEL|KERNELS|NAME|SYMLINK|SUBSYSTEM|SUBSYSTEMS|DRIVER|DRIVERS|ATTR|ATTRS|TAG|TAGS|ENV|TEST|PROGRAM|RESULT)$/
      is_assign = key ~ /^(NAME|SYMLINK|OWNER|GROUP|MODE|TAG|ENV|ATTR|RUN|IMPORT|OPTIONS|LABEL|GOTO)$/
      if ((op == "==" || op == "!=") && !is_match) { printf "line %d: %s cannot be matched\n", NR, key; bad = 1 }
      if (op != "==" && op != "!=" && !is_assign) { printf "line %d: %s cannot be assigned\n", NR, key; bad = 1 }
    }
  }
  END { exit bad }' "${rules}" || bad "60-sunvo.rules does not parse"
for name in sunvo-left sunvo-right; do
  grep -q "SYMLINK+=\"${name}\"" "${rules}" || bad "60-sunvo.rules names no /dev/${name}"
done
grep -q 'KERNEL=="gpiochip' "${rules}" || bad "60-sunvo.rules has no GPIO chip rule"

# --- 6. the installed config's paths ------------------------------------------------------------
# config_values FILE: "dotted.key value" for every scalar of a block-style YAML file (comments and
# quotes stripped); flow mappings ({a: 1}) come out whole and contain no path.
config_values() {
  awk '
    /^[[:space:]]*(#|$)/ { next }
    {
      match($0, /^ */); indent = RLENGTH; line = substr($0, indent + 1)
      k = line; if (!sub(/:.*/, "", k)) next
      v = line; if (!sub(/^[^:]*:[[:space:]]*/, "", v)) next
      while (depth > 0 && ind[depth] >= indent) depth--
      depth++; ind[depth] = indent; key[depth] = k
      sub(/[[:space:]]+#.*$/, "", v); sub(/[[:space:]]+$/, "", v); gsub(/^["\047]|["\047]$/, "", v)
      if (v == "") next
      dotted = key[1]; for (i = 2; i <= depth; ++i) dotted = dotted "." key[i]
      print dotted, v
    }' "$1"
}
if [ "${has_rover}" -eq 1 ]; then
  cfg_file="${WORK}/root/etc/sunvo/rover.yaml"
  symlinks="$(sed -n 's/.*SYMLINK+="\([^"]*\)".*/\1/p' "${rules}" | sort -u)"
  gpio_globs="$(sed -n '/SUBSYSTEM=="gpio"/s/.*KERNEL=="\([^"]*\)".*/\1/p' "${rules}")"
  unit_dirs=""
  # shellcheck disable=SC2013  # each directive lists folders separated by spaces
  for d in $(sed -n 's/^LogsDirectory=//p' "${unit}"); do unit_dirs+=" /var/log/${d}"; done
  # shellcheck disable=SC2013
  for d in $(sed -n 's/^StateDirectory=//p' "${unit}"); do unit_dirs+=" /var/lib/${d}"; done
  under_unit_dir() {
    for d in ${unit_dirs}; do
      case "$1" in "${d}" | "${d}"/*) return 0 ;; esac
    done
    return 1
  }
  paths=0
  while read -r key value; do
    if [ "${key##*.}" = "gpio_chip" ]; then
      chip="${value#/dev/}"
      matched=0
      for glob in ${gpio_globs}; do
        # shellcheck disable=SC2053  # the right side is a udev (shell) glob
        [[ "${chip}" == ${glob} ]] && matched=1
      done
      [ "${matched}" -eq 1 ] || bad "rover.yaml ${key}: ${value} matches no GPIO rule of 60-sunvo.rules ($(words "${gpio_globs}"))"
      continue
    fi
    case "${value}" in
      */*) ;;
      *) continue ;;
    esac
    paths=$((paths + 1))
    if [ "${value#/}" = "${value}" ]; then
      bad "rover.yaml ${key}: ${value} is relative (the service runs in /)"
    elif [ "${value#/dev/}" != "${value}" ]; then
      if grep -qxF "${value#/dev/}" <<<"${symlinks}"; then
        echo "check_deb: rover.yaml ${key}: ${value} <- SYMLINK of 60-sunvo.rules"
      else
        bad "rover.yaml ${key}: ${value} is no SYMLINK of 60-sunvo.rules ($(words "${symlinks}"))"
      fi
    elif [ -f "${WORK}/root${value}" ]; then
      echo "check_deb: rover.yaml ${key}: ${value} <- in the package"
      card="${value%.onnx}.json"
      if [ "${card}" != "${value}" ] && [ -f "${WORK}/root${card}" ]; then
        want="$(sed -n 's/.*"model_sha256": *"\([0-9a-f]*\)".*/\1/p' "${WORK}/root${card}")"
        have="$(sha256sum "${WORK}/root${value}" | cut -d' ' -f1)"
        [ "${want}" = "${have}" ] || bad "${value}: sha256 ${have}, its model card ${card} says '${want}'"
      fi
    elif under_unit_dir "${value}"; then
      echo "check_deb: rover.yaml ${key}: ${value} <- in a folder systemd makes for sunvo.service"
    else
      bad "rover.yaml ${key}: ${value} is not in the package"
    fi
  done < <(config_values "${cfg_file}")
  [ "${paths}" -gt 0 ] || bad "rover.yaml: no path found (config_values cannot read it)"
fi

# --- 7. the command-line convention ----------------------------------------------------------
if [ "${ARCH}" = "${HOST_ARCH}" ]; then
  version="$(field Version)"
  for f in "${WORK}"/root/usr/bin/*; do
    p="$(basename "${f}")"
    if ! out="$("${f}" --help 2>&1)" || ! grep -q "^Usage: ${p}" <<<"${out}"; then
      bad "${p} --help: no exit 0 with 'Usage: ${p}': ${out:0:200}"
    fi
    if ! out="$("${f}" --version 2>&1)" || [ "${out}" != "${p} ${version}" ]; then
      bad "${p} --version: '${out:0:200}', not '${p} ${version}' with exit 0"
    fi
  done
  echo "check_deb: every program answers --help and --version (${version})"
fi

size="$(stat -c %s "${DEB}")"
echo "check_deb: $(basename "${DEB}"): ${size} bytes, Installed-Size $(field Installed-Size) KiB, $(find "${WORK}/root" -type f | wc -l) files, Depends: ${depends}"
if [ "${fail}" -ne 0 ]; then
  echo "check_deb: $(basename "${DEB}") FAILED"
  exit 1
fi
echo "check_deb: $(basename "${DEB}") ok"
