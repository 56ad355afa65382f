#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Install everything surfcomp needs on Debian 12 (FreeCAD 0.20), Debian 13 (FreeCAD 1.0) or
# Debian testing/sid (FreeCAD 1.1); run as root. Idempotent: a second run skips what is
# installed. Used by the README's two commands, by .ci/run and inside the version matrix.
#
# OpenCamLib (for CAM's 3D Surface operation) and the linter ruff come from Debian where
# Debian packages them (python3-opencamlib from 13, ruff in sid) and from PyPI only where it
# does not.
set -euo pipefail

APT_PACKAGES=(
  freecad-python3        # FreeCAD with Part, CAM/Path and the GUI, for Debian's python3
  python3-numpy python3-scipy python3-matplotlib python3-pytest
  xvfb xauth             # GUI tests under xvfb-run
  chromium               # headless screenshot of the HTML report in tests
  git                    # the Addon Manager test clones the checkout
  python3-hypothesis     # property-based tests (tests/fuzz)
  python3-pytest-xdist   # the tests in parallel on the machine's cores (tools/test.sh)
  linuxcnc-uspace        # rs274, LinuxCNC's own G-code interpreter, reads our G-code in tests
)
#: the linter, the same version everywhere (Debian's where the archive has ruff, else PyPI)
RUFF_VERSION=0.16.10

installed() {
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"
}

# the candidate version apt would install, empty when the archive has no such package
candidate() {
  apt-cache policy "$1" 2>/dev/null | awk '/Candidate:/ { if ($2 != "(none)") print $2 }'
}

apt_install() {
  echo "surfcomp setup: installing Debian packages: $*"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}

export DEBIAN_FRONTEND=noninteractive
missing=()
for p in "${APT_PACKAGES[@]}"; do
  installed "$p" || missing+=("$p")
done
# something to install, or no package lists yet (a fresh root): whether the archive has
# python3-opencamlib is known only after an update
if [ ${#missing[@]} -gt 0 ] || ! compgen -G "/var/lib/apt/lists/*_Packages*" >/dev/null; then
  apt-get update -qq
fi

# python3-opencamlib and ruff from Debian where the archive has them, else from PyPI
pypi=()
if installed python3-opencamlib || [ -n "$(candidate python3-opencamlib)" ]; then
  installed python3-opencamlib || missing+=(python3-opencamlib)
elif ! /usr/bin/python3 -c "import opencamlib.ocl" 2>/dev/null; then
  pypi+=("opencamlib>=2023.1")
fi
if installed ruff || [ -n "$(candidate ruff)" ]; then
  installed ruff || missing+=(ruff)
elif [ "$(ruff --version 2>/dev/null)" != "ruff $RUFF_VERSION" ]; then
  pypi+=("ruff==$RUFF_VERSION")
fi
if [ ${#pypi[@]} -gt 0 ] && ! installed python3-pip; then
  missing+=(python3-pip)
fi

if [ ${#missing[@]} -gt 0 ]; then
  apt_install "${missing[@]}"
else
  echo "surfcomp setup: Debian packages already installed"
fi

if [ ${#pypi[@]} -gt 0 ]; then
  # only what this Debian release does not package (Debian 12: opencamlib and ruff;
  # Debian 13: ruff); --break-system-packages because pip may not write there otherwise
  echo "surfcomp setup: installing from PyPI (not packaged by this Debian): ${pypi[*]}"
  /usr/bin/python3 -m pip install --quiet --break-system-packages --root-user-action=ignore \
    "${pypi[@]}"
else
  echo "surfcomp setup: nothing needed from PyPI"
fi

# Link this checkout into FreeCAD's user Mod folder, as the Addon Manager would clone it:
# FreeCAD then puts it on sys.path at start-up (workbench, freecadcmd) and restores the
# proxies of surfcomp objects in saved documents (it refuses proxies from other places).
mod_dir="${XDG_DATA_HOME:-$HOME/.local/share}/FreeCAD/Mod"
repo="$(cd "$(dirname "$0")/.." && pwd)"
mkdir -p "$mod_dir"
if [ "$(readlink -f "$mod_dir/surfcomp" 2>/dev/null)" != "$repo" ]; then
  if [ -e "$mod_dir/surfcomp" ] && [ ! -L "$mod_dir/surfcomp" ]; then
    echo "surfcomp setup: $mod_dir/surfcomp exists and is not a link; leaving it alone" >&2
  else
    ln -sfn "$repo" "$mod_dir/surfcomp"
    echo "surfcomp setup: linked $repo into $mod_dir"
  fi
else
  echo "surfcomp setup: already linked into $mod_dir"
fi

# The command line as a command on PATH, run by Debian's Python (which has FreeCAD, numpy
# and scipy) whatever python3 comes first on PATH, with this checkout's package
launcher=/usr/local/bin/surfcomp
want="#!/bin/sh
# surfcomp's command line (written by $repo/tools/install.sh)
if [ ! -f \"$repo/surfcomp/__main__.py\" ]; then
  echo \"surfcomp: the checkout this command runs, $repo, is gone; run tools/install.sh in a checkout of surfcomp\" >&2
  exit 2
fi
PYTHONPATH=\"$repo\${PYTHONPATH:+:\$PYTHONPATH}\" exec /usr/bin/python3 -m surfcomp \"\$@\""
if [ "$(cat "$launcher" 2>/dev/null)" != "$want" ]; then
  if [ -e "$launcher" ] && ! grep -q "^# surfcomp's command line" "$launcher"; then
    echo "surfcomp setup: $launcher exists and is not surfcomp's; leaving it alone" >&2
  else
    printf '%s\n' "$want" >"$launcher.new" && chmod 755 "$launcher.new" && mv "$launcher.new" "$launcher"
    echo "surfcomp setup: installed the command $launcher"
  fi
else
  echo "surfcomp setup: the command $launcher is installed"
fi

# What was found: the versions every result depends on
/usr/bin/python3 "$repo/tools/versions.py" --prefix "surfcomp setup: found "
echo "surfcomp setup: found $(ruff --version)"
