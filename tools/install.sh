#!/usr/bin/env bash
# Install everything surfcomp needs on Debian 12 (run as root; idempotent: a second
# run skips what is installed). Used by the README's two commands and by .ci/run.
set -euo pipefail

APT_PACKAGES=(
  freecad-python3        # FreeCAD 0.20 (Part, Path, GUI) for Debian's python3
  python3-numpy python3-scipy python3-matplotlib python3-pytest
  python3-pip            # to install OpenCamLib from PyPI
  xvfb xauth             # GUI tests under xvfb-run
  chromium               # headless screenshot of the HTML report in tests
)
PIP_PACKAGES=(
  "opencamlib>=2023.1"   # Path's 3D Surface operation (import ocl)
)

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "surfcomp setup: installing Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "surfcomp setup: Debian packages already installed"
fi

if ! /usr/bin/python3 -c "import opencamlib.ocl" 2>/dev/null; then
  echo "surfcomp setup: installing from PyPI: ${PIP_PACKAGES[*]}"
  /usr/bin/python3 -m pip install --quiet --break-system-packages --root-user-action=ignore \
    "${PIP_PACKAGES[@]}"
else
  echo "surfcomp setup: OpenCamLib already installed"
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
