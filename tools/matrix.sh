#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The version matrix: run the README's command 2 (install everything, run every test) on
# each FreeCAD that users have, and print one summary line per FreeCAD version.
#
#   bash tools/matrix.sh [ENTRY...]          ENTRY: host, trixie (FreeCAD 1.0), sid (FreeCAD 1.1)
#   bash tools/matrix.sh prepare [ENTRY...]  only build/refresh the roots and install in them
#
# Default entries: trixie sid. "host" runs command 2 in this checkout (FreeCAD 0.20 on
# Debian 12). Every other entry is a Debian root made with debootstrap from Debian's
# archive, cached in $SURFCOMP_MATRIX_DIR (default /var/cache/surfcomp-matrix) and rebuilt
# when it is missing or broken. The checkout (HEAD plus uncommitted changes) is cloned into
# the root and command 2 runs there. Needs root. Exit status: 0 only when every entry passed.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
cache="${SURFCOMP_MATRIX_DIR:-/var/cache/surfcomp-matrix}"
mirror="${SURFCOMP_DEBIAN_MIRROR:-http://deb.debian.org/debian}"
logs="$cache/logs"
# the environment inside a root: nothing of the host's (its PATH may hold another python3)
clean_env=(env -i HOME=/root LANG=C.UTF-8 LC_ALL=C.UTF-8 TERM=dumb
           PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin)

say() { echo "matrix: $*" >&2; }

suite_of() {
  case "$1" in
    trixie|1.0) echo trixie ;;
    sid|1.1) echo sid ;;
    host|0.20) echo host ;;
    *) say "unknown entry '$1' (expected host, trixie or sid)"; exit 2 ;;
  esac
}

mounted=()
unmount_all() {
  local m
  for m in "${mounted[@]}"; do
    umount -R "$m" 2>/dev/null || umount -l "$m" 2>/dev/null || true
  done
  mounted=()
}
trap unmount_all EXIT
trap 'unmount_all; exit 130' INT
trap 'unmount_all; exit 143' TERM

mount_root() {
  local root=$1 d
  for d in proc sys dev; do
    mkdir -p "$root/$d"
    if ! mountpoint -q "$root/$d"; then
      case $d in
        proc) mount -t proc proc "$root/proc" ;;
        *) mount --rbind "/$d" "$root/$d"; mount --make-rslave "$root/$d" ;;
      esac
    fi
    mounted+=("$root/$d")
  done
}

unmount_root() {
  local root=$1 d
  for d in dev sys proc; do
    umount -R "$root/$d" 2>/dev/null || umount -l "$root/$d" 2>/dev/null || true
  done
}

in_root() {
  local root=$1; shift
  chroot "$root" "${clean_env[@]}" "$@"
}

# a root is usable when debootstrap finished, its python runs and dpkg has nothing half-done
root_ok() {
  local root=$1
  [ -f "$root/.surfcomp-root" ] || return 1
  mount_root "$root"
  in_root "$root" /usr/bin/python3 -c "pass" >/dev/null 2>&1 || return 1
  [ -z "$(in_root "$root" dpkg --audit 2>/dev/null)" ] || return 1
}

build_root() {
  local suite=$1 root=$2
  if [ -d "$root" ]; then
    say "$suite: the cached root is missing or broken; rebuilding it"
    unmount_root "$root"
    if findmnt -rn -o TARGET | grep -q "^$root/"; then
      say "$suite: something is still mounted under $root; not deleting it"; return 1
    fi
    rm -rf --one-file-system "$root"
  fi
  command -v debootstrap >/dev/null || {
    say "installing debootstrap"
    DEBIAN_FRONTEND=noninteractive apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap >/dev/null
  }
  say "$suite: debootstrap --variant=minbase $suite (takes a minute or two)"
  mkdir -p "$(dirname "$root")" "$logs"
  debootstrap --variant=minbase "$suite" "$root" "$mirror" >"$logs/$suite.debootstrap.log" 2>&1 || {
    say "$suite: debootstrap failed (see $logs/$suite.debootstrap.log)"; tail -5 "$logs/$suite.debootstrap.log" >&2
    return 1
  }
  touch "$root/.surfcomp-root"
}

configure_root() {
  local suite=$1 root=$2
  mkdir -p "$root/etc/ssl/certs" "$root/etc/apt/apt.conf.d" "$root/usr/local/share/ca-certificates"
  cp /etc/ssl/certs/ca-certificates.crt "$root/etc/ssl/certs/ca-certificates.crt"
  # the root's ca-certificates package rebuilds that bundle when it is installed or updated;
  # a local certificate file keeps this machine's authorities in the rebuilt one (pip needs them)
  cp /etc/ssl/certs/ca-certificates.crt "$root/usr/local/share/ca-certificates/surfcomp-host.crt"
  [ -f /etc/pip.conf ] && cp /etc/pip.conf "$root/etc/pip.conf"
  [ -f /etc/resolv.conf ] && cp -L /etc/resolv.conf "$root/etc/resolv.conf"
  echo "deb $mirror $suite main" >"$root/etc/apt/sources.list"
  if [ "$suite" = sid ]; then
    # sid's Release file may be served past its Valid-Until date; only this root accepts it
    echo 'Acquire::Check-Valid-Until "false";' >"$root/etc/apt/apt.conf.d/99surfcomp-valid-until"
  fi
}

# clone the checkout into the root: HEAD, then the working tree's changes on top, so the
# matrix tests what is about to be committed
clone_into() {
  local root=$1 dst="$1/root/surfcomp"
  rm -rf "$dst"
  git clone -q --no-hardlinks "$repo" "$dst"
  (cd "$repo" && git ls-files -co --exclude-standard -z) |
    (cd "$repo" && tar --null -T - -cf - 2>/dev/null) | tar -xf - -C "$dst"
  (cd "$repo" && git ls-files -d -z) | (cd "$dst" && xargs -0 -r rm -f)
}

prepare() {
  local suite=$1 root="$cache/$1"
  mkdir -p "$logs"
  if ! root_ok "$root"; then
    unmount_root "$root"
    build_root "$suite" "$root"
  fi
  configure_root "$suite" "$root"
  mount_root "$root"
  clone_into "$root"
  # the install half of command 2; the run below repeats it and finds everything there
  say "$suite: tools/install.sh in the root"
  in_root "$root" bash -c "cd /root/surfcomp && bash tools/install.sh" >"$logs/$suite.install.log" 2>&1 || {
    say "$suite: install.sh failed (see $logs/$suite.install.log)"; tail -20 "$logs/$suite.install.log" >&2
    return 1
  }
}

# the README's command 2, taken from the README itself so the two cannot drift apart
command2() {
  grep -m1 -E '^bash tools/install.sh && bash tools/test.sh' "$repo/README.md"
}

# run_entry SUITE [FIRST X SERVER NUMBER] [PYTEST WORKERS]
run_entry() {
  local suite=$1 log="$logs/$1.test.log" rc=0 cmd versions result
  cmd=$(command2)
  [ -n "$cmd" ] || { say "README.md has no command 2"; return 1; }
  if [ "$suite" = host ]; then
    say "host: $cmd"
    (cd "$repo" && bash -c "$cmd") >"$log" 2>&1 || rc=$?
    versions=$(/usr/bin/python3 "$repo/tools/versions.py" --summary 2>/dev/null) || true
  else
    local root="$cache/$suite"
    mount_root "$root"
    say "$suite: $cmd"
    # the roots share the host's network namespace, where X servers listen: each root's
    # Xvfb gets numbers of its own (tools/test.sh), as the roots run side by side
    # and its share of the cores for pytest's workers (tools/test.sh)
    in_root "$root" bash -c "cd /root/surfcomp && export SURFCOMP_XVFB_FROM=${2:-99} \
      SURFCOMP_TEST_WORKERS=${3:-1} && $cmd" \
      >"$log" 2>&1 || rc=$?
    versions=$(in_root "$root" /usr/bin/python3 /root/surfcomp/tools/versions.py --summary 2>/dev/null) || true
  fi
  # pytest's result lines: "560 passed in 347.38s (0:05:47)" or "2 failed, 558 passed in
  # ..." (a full parallel run has two: the rest, then the latency GUI sessions); every one counts
  local results
  results=$(grep -E '[0-9]+ (passed|failed|errors?)\b.* in [0-9.]+s' "$log" | sed -E 's/^=+ //; s/ =+$//')
  result=$(tr '\n' ';' <<<"$results" | sed -E 's/;$//; s/;/; /g')
  if [ "$rc" != 0 ] || [ -z "$result" ] || grep -qE '[0-9]+ (failed|errors?|skipped)' <<<"$results"; then
    [ "$rc" = 0 ] && rc=1
    say "$suite: FAILED (exit $rc); the end of $log:"
    tail -60 "$log" >&2
  fi
  local where="Debian $suite root"
  [ "$suite" = host ] && where="this machine, Debian $(. /etc/os-release && echo "${VERSION_ID:-?} ${VERSION_CODENAME:-}")"
  echo "${versions:-FreeCAD ?} [$where]: ${result:-no test result} (exit $rc)" >>"$logs/summary.txt"
  return "$rc"
}

main() {
  [ "$(id -u)" = 0 ] || { say "run me as root (debootstrap and chroot need it)"; exit 2; }
  local only_prepare=0 entries=() roots=() e status=0 host=0 bg=""
  if [ "${1:-}" = prepare ]; then only_prepare=1; shift; fi
  for e in ${*:-trixie sid}; do entries+=("$(suite_of "$e")"); done
  for e in "${entries[@]}"; do
    if [ "$e" = host ]; then host=1; else roots+=("$e"); fi
  done
  mkdir -p "$logs"
  : >"$logs/summary.txt"
  prepare_all() {
    local r s=0
    for r in "${roots[@]}"; do
      prepare "$r" || { echo "FreeCAD on Debian $r: the root could not be prepared" >>"$logs/summary.txt"; s=1; }
    done
    return $s
  }
  if [ "$only_prepare" = 1 ]; then
    prepare_all || status=1
    cat "$logs/summary.txt"
    return "$status"
  fi
  if [ "$host" = 1 ] && [ ${#roots[@]} -gt 0 ]; then
    # the roots download and install while the host suite runs
    ( prepare_all ) >"$logs/prepare.log" 2>&1 &
    bg=$!
  elif [ ${#roots[@]} -gt 0 ]; then
    prepare_all || status=1
  fi
  if [ "$host" = 1 ]; then run_entry host || status=1; fi
  if [ -n "$bg" ]; then
    wait "$bg" || { status=1; cat "$logs/prepare.log" >&2; }
  fi
  # the roots run side by side, each pytest with its share of the cores (one worker each on
  # 2 cores)
  local pids=() n=0 p workers
  workers=$(( $(nproc) / (${#roots[@]} > 0 ? ${#roots[@]} : 1) ))
  [ "$workers" -ge 1 ] || workers=1
  for e in "${roots[@]}"; do
    grep -q "Debian $e: the root could not" "$logs/summary.txt" && continue
    mount_root "$cache/$e"           # here, so that the exit trap unmounts it
    n=$((n + 1))
    run_entry "$e" $((100 + 20 * n)) "$workers" &
    pids+=("$!")
  done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
  echo
  echo "=== version matrix (logs in $logs) ==="
  cat "$logs/summary.txt"
  return "$status"
}

main "$@"
