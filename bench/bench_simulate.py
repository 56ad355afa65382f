# SPDX-License-Identifier: LGPL-2.1-or-later
"""Virtual machining: every preset's time and the paper's table beside the simulated one,
then the papers' table on the bundled example's face.

    /usr/bin/python3 bench/bench_simulate.py [--presets [NAME ...]] [--grid [N ...]]
        [--replicas 4] [--sigma 0.0015 ...] [--maps OUT.png [--maps-preset NAME]]

Per preset: the wall seconds of the simulation itself
(``surfcomp.core.simulation.presets.run_preset``, seed 0) and of the whole command ``python3 -m
surfcomp simulate --preset NAME`` in a fresh
process (imports included), the load average of the machine, and the side-by-side table.
Per example case: wall seconds and the before/after table (mean (range) over replicas)
for the default model, and the per-replica standard deviations (mirror paper Tab. 2
form). ``--maps OUT.png`` writes the simulated parts of ``--maps-preset`` (default
mirror2019-s1) as maps (README).
No FreeCAD needed: the faces are built in core.
"""

import argparse
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from examples.make_example import example_surface  # noqa: E402
from surfcomp.core.simulation import presets  # noqa: E402
from surfcomp.core.simulation import simulate as sm  # noqa: E402


def bench_presets(names, maps=None, maps_preset=None):
    for name in names:
        draw = bool(maps) and name == maps_preset
        t = time.perf_counter()
        res = presets.run_preset(name, seed=0, keep=draw)
        core = time.perf_counter() - t
        t = time.perf_counter()
        out = subprocess.run([sys.executable, "-m", "surfcomp", "simulate", "--preset", name,
                              "--quiet"], cwd=ROOT, capture_output=True, text=True)
        command = time.perf_counter() - t
        if out.returncode != 0:
            raise SystemExit(out.stderr)
        print("== preset %s: simulation %.2f s, whole command %.2f s (load average %.2f, "
              "%d cores)" % (name, core, command, os.getloadavg()[0], os.cpu_count()))
        print(res.side_table())
        print()
        if draw:
            from matplotlib.backends.backend_agg import FigureCanvasAgg

            from surfcomp.io.html_report import simulation_maps, simulation_maps_figure

            fig = simulation_maps_figure(simulation_maps(res), title="%s, replica 1 (seed 0)"
                                         % name)
            FigureCanvasAgg(fig)
            fig.savefig(maps, dpi=50)
            print("wrote %s" % maps)
            print()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", nargs="*", default=list(presets.PRESETS))
    ap.add_argument("--grid", type=int, nargs="*", default=[23, 45])
    ap.add_argument("--replicas", type=int, default=4)
    ap.add_argument("--sigma", type=float, nargs="*", default=[0.0015, 0.004])
    ap.add_argument("--correlation-length", type=float, default=0.0)
    ap.add_argument("--maps", metavar="OUT.png")
    ap.add_argument("--maps-preset", default="mirror2019-s1", metavar="NAME")
    args = ap.parse_args()
    bench_presets(args.presets, args.maps, args.maps_preset)
    surf = example_surface()
    for g in args.grid:
        for s in args.sigma:
            model = sm.MachiningModel(sigma=s, correlation_length=args.correlation_length)
            t = time.perf_counter()
            res = sm.simulate(surf, 1, model, grid=(g, g), replicas=args.replicas, seed=2022)
            dt = time.perf_counter() - t
            print("== grid %dx%d, sigma %.1f um, L %.1f mm, %d replicas x %d methods: %.2f s"
                  % (g, g, s * 1e3, args.correlation_length, args.replicas, len(res.labels), dt))
            print(res.table())
            print(res.replica_table("std"))
            print()


if __name__ == "__main__":
    main()
