# SPDX-License-Identifier: LGPL-2.1-or-later
"""The Python API under a Python that cannot import FreeCAD: importing it works, the
numpy-only calls run, and the calls that need FreeCAD say what to install or run."""

import json
import os
import subprocess
import sys
import textwrap

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

#: run first in the child: FreeCAD and its modules cannot be imported, as in a Python
#: without FreeCAD (the host's FreeCAD would otherwise be found by surfcomp.app.fcenv)
NO_FREECAD = textwrap.dedent("""
    import importlib.abc, sys

    class NoFreeCAD(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ("FreeCAD", "FreeCADGui", "Part", "Path", "Mesh"):
                raise ModuleNotFoundError("No module named %r" % name, name=name)
            return None

    sys.meta_path.insert(0, NoFreeCAD())
""")


def run(body):
    code = NO_FREECAD + textwrap.dedent(body)
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         timeout=300, env=dict(os.environ, PYTHONPATH=ROOT))
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_import_needs_neither_freecad_nor_numpy():
    got = run("""
        import json, sys
        import surfcomp
        light = sorted(m for m in ("numpy", "scipy", "FreeCAD") if m in sys.modules)
        import surfcomp.api
        print(json.dumps({"light": light, "freecad": "FreeCAD" in sys.modules,
                          "same": surfcomp.compensate is surfcomp.api.compensate,
                          "names": sorted(surfcomp.api.__all__) == sorted(surfcomp.API)}))
    """)
    assert got == {"light": [], "freecad": False, "same": True, "names": True}


def test_numpy_calls_run_and_freecad_calls_say_what_to_do():
    got = run("""
        import json, sys
        import surfcomp
        from surfcomp.core.simulation import presets

        surface, outward = presets.get_preset("mirror2019-s3").surface()

        class Nominal:                      # a core surface and its outward side
            pass

        nominal = Nominal()
        nominal.surface, nominal.outward = surface, outward
        points = surfcomp.read_measurements("examples/measurements.csv")
        out = {"points": len(points)}
        try:
            surfcomp.load_nominal("examples/nominal.step")
        except surfcomp.FreeCADRequired as exc:
            out["load"] = str(exc)
            out["is_import_error"] = isinstance(exc, ImportError)
        try:
            surfcomp.compensate(nominal, points, mask_size=4)
        except surfcomp.InputError as exc:
            out["bad_option"] = [str(exc), list(exc.options)]
        try:
            surfcomp.options(mask=5)
        except surfcomp.InputError as exc:
            out["unknown"] = str(exc)
        out["freecad_imported"] = "FreeCAD" in sys.modules
        print(json.dumps(out))
    """)
    assert got["points"] == 2025
    assert got["is_import_error"] is True
    assert got["load"].startswith("surfcomp.load_nominal needs FreeCAD, and this Python (%s) "
                                  "cannot import it: install FreeCAD for it (Debian: apt-get "
                                  "install freecad-python3" % sys.executable), got["load"]
    assert "run the script with /usr/bin/python3" in got["load"]
    assert got["bad_option"] == ["mask_size 4: expected an odd whole number from 1 to 201 "
                                 "(3, 5, 7, ...)", ["mask_size"]]
    assert got["unknown"].startswith("unknown option mask (expected some of accept_stock, ")
    assert got["freecad_imported"] is False


def test_compensate_on_core_arrays_without_freecad():
    """A virtual measurement of a preset surface, compensated without FreeCAD: the
    intended correction of ``raw`` is the deviation itself (Werner 2022 eq. 1-2)."""
    got = run("""
        import json
        import numpy as np
        import surfcomp
        from surfcomp.core.surface import bspline
        from surfcomp.core.simulation import presets

        surface, outward = presets.get_preset("mirror2019-s3").surface()
        us = np.linspace(*surface.u_range, 12)
        vs = np.linspace(*surface.v_range, 10)
        S, Su, Sv = bspline.evaluate_grid(surface, us, vs, order=1)
        n = np.cross(Su, Sv) * outward
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        uu, vv = np.meshgrid(np.linspace(0, 1, 12), np.linspace(0, 1, 10), indexing="ij")
        d = 0.01 * np.sin(3 * uu) * np.cos(2 * vv)
        rows, cols = np.indices(d.shape)
        ms = surfcomp.MeasurementSet(nominal=S.reshape(-1, 3), normal=n.reshape(-1, 3),
                                     deviation=d.ravel(), row=rows.ravel(), col=cols.ravel())

        class Nominal:
            pass

        nominal = Nominal()
        nominal.surface, nominal.outward = surface, outward
        result = surfcomp.compensate(nominal, ms, method="raw")
        delta = result.per_point("delta")
        try:
            surfcomp.write_face(result, "never.step")
        except surfcomp.InputError as exc:
            refused = str(exc)
        print(json.dumps({"err": float(np.abs(delta - d.ravel()).max()),
                          "rms": result.statistics["deviation"].rms,
                          "rms_ref": float(np.sqrt(np.mean(d ** 2))),
                          "built": result.corrected is not None, "refused": refused}))
    """)
    assert got["err"] <= 1e-15
    assert abs(got["rms"] - got["rms_ref"]) <= 1e-15
    assert got["built"] is True
    assert got["refused"] == ("surfcomp.write_face: the result's nominal is no loaded face "
                              "(use surfcomp.load_nominal)")
    assert not os.path.exists(os.path.join(ROOT, "never.step"))
