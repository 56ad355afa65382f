#!/usr/bin/env bash
# Install everything surfcomp needs on Debian 12 (FreeCAD 0.20), Debian 13 (FreeCAD 1.0) or
# Debian testing/sid (FreeCAD 1.1); run as root. Idempotent: a second run skips what is
# installed. Used by the README's two commands, by .ci/run and inside the version matrix.
#
# OpenCamLib (for CAM's 3D Surface operation) comes from Debian where Debian packages it
# (python3-opencamlib, Debian 13 and later) and from PyPI only where it does not (Debian 12).
set -euo pipefail

APT_PACKAGES=(
  freecad-python3        # FreeCAD with Part, CAM/Path and the GUI, for Debian's python3
  python3-numpy python3-scipy python3-matplotlib python3-pytest
  xvfb xauth             # GUI tests under xvfb-run
  chromium               # headless screenshot of the HTML report in tests
  git                    # the Addon Manager test clones the checkout
)

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

opencamlib_from=pypi
if installed python3-opencamlib || [ -n "$(candidate python3-opencamlib)" ]; then
  opencamlib_from=debian
  installed python3-opencamlib || missing+=(python3-opencamlib)
else
  installed python3-pip || missing+=(python3-pip)
fi

if [ ${#missing[@]} -gt 0 ]; then
  apt_install "${missing[@]}"
else
  echo "surfcomp setup: Debian packages already installed"
fi

if [ "$opencamlib_from" = pypi ]; then
  if /usr/bin/python3 -c "import opencamlib.ocl" 2>/dev/null; then
    echo "surfcomp setup: OpenCamLib already installed (PyPI)"
  else
    # Debian 12 has no python3-opencamlib: the PyPI wheel is the only source there
    echo "surfcomp setup: installing from PyPI: opencamlib (Debian has no python3-opencamlib here)"
    /usr/bin/python3 -m pip install --quiet --break-system-packages --root-user-action=ignore \
      "opencamlib>=2023.1"
  fi
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

# What was found: the versions every result depends on
/usr/bin/python3 "$repo/tools/versions.py" --prefix "surfcomp setup: found "
