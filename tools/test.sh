#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Run the lint gate and the whole test suite: pure, FreeCAD headless and GUI (under Xvfb).
# Arguments go to pytest (e.g. tests/pure); the lint gate runs only for a full run.
set -euo pipefail
cd "$(dirname "$0")/.."
# the suite starts hundreds of Python processes (the command line, freecadcmd, GUI
# sessions): with PYTHONDONTWRITEBYTECODE set (some CI images set it) none of them finds the
# modules compiled, and each compiles every surfcomp module it imports again (0.25 s of CPU
# for the routes' modules alone), and every pytest worker rewrites every test module's
# asserts again; the compiled files go to __pycache__ folders, which git ignores
unset PYTHONDONTWRITEBYTECODE
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
# FreeCAD restores the proxies of saved surfcomp objects only from modules in its Mod
# folders (a security rule of its current releases), so the tests that open a saved document
# in a fresh FreeCAD need this checkout there. Where FreeCAD's Mod folder links another
# checkout (tools/install.sh ran in that one), this run gets a FreeCAD data folder of its own
# that links this checkout, and leaves the user's alone.
mod_dirs() {
  freecadcmd -c "import FreeCAD, os; print('MODDIRS ' + repr([os.path.realpath(d) for d in FreeCAD.__ModDirs__]))" 2>/dev/null | grep '^MODDIRS ' || true
}
here=$(pwd -P)
if command -v freecadcmd >/dev/null && ! mod_dirs | grep -qF "'$here'"; then
  mkdir -p "$scratch/data/FreeCAD/Mod" "$scratch/data/Mod"
  ln -s "$here" "$scratch/data/FreeCAD/Mod/surfcomp"   # XDG_DATA_HOME's layout
  ln -s "$here" "$scratch/data/Mod/surfcomp"           # FREECAD_USER_HOME's (FreeCAD 1.x)
  export XDG_DATA_HOME="$scratch/data"
  if [ -n "${FREECAD_USER_HOME:-}" ]; then export FREECAD_USER_HOME="$scratch/data"; fi
  if mod_dirs | grep -qF "'$here'"; then
    echo "surfcomp tests: FreeCAD's Mod folder links another checkout; this run uses its own FreeCAD data folder, linking this one"
  else
    echo "surfcomp tests: warning: FreeCAD does not load this checkout ($here) as a Mod; the tests that reopen saved documents will fail" >&2
  fi
fi
# the test modules that hold tests marked $1 (for a part that runs only those: collecting
# the whole suite to choose a few costs about a second)
marked_modules() {
  grep -l "mark\.$1" tests/*/test_*.py || true
}
if [ $# -eq 0 ]; then
  echo "surfcomp tests: lint with $(ruff --version) (pyproject.toml)"
  ruff check --no-cache .
  # the tests against converged reference solvers, once per OpenBLAS kernel this CPU can run
  # (OpenBLAS picks its kernel by CPU; a reference that stopped at rounding level passed on
  # one kernel and failed on another); only the modules that hold such tests are collected
  # (the kernels side by side, one process and one OpenBLAS thread each, so that neither
  # spins on the other's core; their output in turn)
  reference_files=$(marked_modules reference_solver)
  logs="$scratch/logs"
  mkdir "$logs"
  pids=()
  for kernel in Haswell:avx2 SkylakeX:avx512f; do
    if grep -qw "${kernel#*:}" /proc/cpuinfo; then
      # shellcheck disable=SC2086
      OPENBLAS_CORETYPE=${kernel%%:*} OPENBLAS_NUM_THREADS=1 SURFCOMP_RECORD_DURATIONS="" \
        /usr/bin/python3 -m pytest -q -p no:cacheprovider \
        -m reference_solver $reference_files >"$logs/${kernel%%:*}" 2>&1 &
      pids+=("$!:${kernel%%:*}")
    fi
  done
  for entry in "${pids[@]}"; do
    ok=0
    wait "${entry%%:*}" || ok=$?
    echo "surfcomp tests: reference solves with OPENBLAS_CORETYPE=${entry#*:}"
    cat "$logs/${entry#*:}"
    [ "$ok" -eq 0 ] || exit "$ok"
  done
fi
# In parallel on the machine's cores with pytest-xdist where it is installed (Debian's
# python3-pytest-xdist, tools/install.sh): the tests that share a module fixture (a shop
# document, a GUI session) on one worker, the rest spread test by test, the longest first
# (tests/conftest.py, tests/schedule.py). One worker more than the cores: a GUI session, a
# FreeCAD child or a command-line run often waits (its X server, FreeCAD's timers, a
# child's recompute), and the extra worker keeps the cores busy meanwhile (measured in
# docs/benchmarks.md, "The suite's time").
# SURFCOMP_TEST_WORKERS=1 runs everything in this one process.
cores=$(nproc 2>/dev/null || echo 1)
workers="${SURFCOMP_TEST_WORKERS:-$(( cores > 1 ? cores + 1 : 1 ))}"
parallel=()
if [ "$workers" -gt 1 ] && /usr/bin/python3 -c "import xdist" 2>/dev/null; then
  parallel=(-n "$workers" --dist loadgroup)
fi
export QTWEBENGINE_CHROMIUM_FLAGS="${QTWEBENGINE_CHROMIUM_FLAGS:---no-sandbox}"
# -a: the first free X server number from SURFCOMP_XVFB_FROM (default 99; the version
# matrix gives each root its own range); in a parallel run each worker's GUI sessions
# start their own X server 5, 10 ... numbers above it (tests/gui/harness.py)
export SURFCOMP_XVFB_FROM="${SURFCOMP_XVFB_FROM:-99}"
run_pytest() {
  xvfb-run -a -n "$SURFCOMP_XVFB_FROM" -s "-screen 0 1600x1200x24" \
    /usr/bin/python3 -m pytest "$@"
}
# a parallel run in two parts: everything but the GUI sessions that measure response times
# on the workers, then those (marked latency) alone on the machine, so that their checks
# (every key press repainted, answered within a bound) measure the GUI and not a
# neighbouring worker's load; both parts always run. Arguments that choose tests by mark
# (-m) run as given, in one part.
chooses_marks() {
  local a
  for a in "$@"; do case "$a" in -m|-m*) return 0 ;; esac; done
  return 1
}
if [ ${#parallel[@]} -gt 0 ] && ! chooses_marks "$@"; then
  late=("$@")
  if [ $# -eq 0 ]; then
    set -- tests/pure tests/fuzz tests/app tests/gui
    # a full run's latency part collects only the modules that hold such tests
    mapfile -t late < <(marked_modules latency)
    [ ${#late[@]} -gt 0 ] || late=("$@")
  fi
  rc=0
  # the workers keep every core busy: a second OpenBLAS thread in one of them (or in a
  # FreeCAD it starts) only spins on a core another worker needs (sched_yield after each
  # call it made parallel), so in this part, unless the caller chose its BLAS threads,
  # each process has one (docs/benchmarks.md, "The suite's time")
  (
    if [ -z "${OPENBLAS_NUM_THREADS:-}${GOTO_NUM_THREADS:-}${OMP_NUM_THREADS:-}" ]; then
      export OPENBLAS_NUM_THREADS=1
    fi
    run_pytest "${parallel[@]}" -m "not scale and not latency" "$@"
  ) || rc=$?
  lrc=0
  run_pytest -m "latency and not scale" "${late[@]}" || lrc=$?
  # 5: no test chosen, as when the arguments name no latency test (or only latency tests)
  if [ "$rc" -eq 5 ] && [ "$lrc" -ne 5 ]; then rc=0; fi
  if [ "$lrc" -ne 0 ] && [ "$lrc" -ne 5 ]; then rc=$lrc; fi
  exit "$rc"
fi
run_pytest "${parallel[@]}" "$@"
