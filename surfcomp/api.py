# SPDX-License-Identifier: LGPL-2.1-or-later
"""surfcomp's Python API: a few calls that take and return surfcomp's own objects.

::

    import surfcomp

    nominal = surfcomp.load_nominal("examples/nominal.step")            # needs FreeCAD
    points = surfcomp.read_measurements("examples/measurements.csv")
    result = surfcomp.compensate(nominal, points, method="filtered", mask_size=5)
    print(result.statistics["deviation"].rms)                           # mm
    surfcomp.write_solid(result, "out/corrected.step")                  # needs FreeCAD

* :func:`read_measurements` and :func:`compensate` need numpy and scipy only;
  :func:`load_nominal` and the writers need FreeCAD. They start it themselves
  (:mod:`surfcomp.app.fcenv`); under a Python that cannot import it they raise
  :class:`~surfcomp.errors.FreeCADRequired`, saying what to install or run instead.
  Importing this module never needs FreeCAD.
* Options are :class:`Options` fields, given as keyword arguments (defaults as the
  command line's) or as an :class:`Options`; errors name them the same way
  (``max_offset``, ``stock``).
* The nominal carries its outward side (``nominal.outward``): no call takes it apart.
* Every failure is a :class:`~surfcomp.errors.SurfcompError` naming the file, line and
  what was expected (:class:`~surfcomp.errors.InputError` for bad input).

The whole command-line job (inputs, options and every output in one transaction) is
:class:`Job` and :func:`run_job`, as ``python3 -m surfcomp compensate`` and job files run it.
"""

import dataclasses
import os
import sys
from dataclasses import dataclass

from .app.file_route import Job, run_job
from .core.compensation.pipeline import Compensation, Options
from .core.compensation.pipeline import compensate as _compensate
from .core.compensation.pipeline import prepare as _prepare
from .core.measurement_set import MeasurementSet
from .errors import FreeCADRequired, InputError, SurfcompError

__all__ = ["Compensation", "FreeCADRequired", "InputError", "Job", "MeasurementSet", "Options",
           "Result", "SurfcompError", "compensate", "load_nominal", "options",
           "read_measurements", "require_freecad", "run_job", "write_document", "write_face",
           "write_solid"]


def require_freecad(what="this call"):
    """Import FreeCAD (its ``Mod`` folders on the path, as ``freecadcmd`` has them) and
    return the module.

    Raises
    ------
    FreeCADRequired
        Under a Python that cannot import FreeCAD: names ``what`` and how to get it.
    """
    from .app import fcenv

    try:
        return fcenv.import_freecad()
    except ImportError as exc:
        raise FreeCADRequired(
            "%s needs FreeCAD, and this Python (%s) cannot import it: install FreeCAD for "
            "it (Debian: apt-get install freecad-python3, or bash tools/install.sh) and run "
            "the script with /usr/bin/python3, or set FREECAD_LIB to the folder holding "
            "FreeCAD.so (%s)" % (what, sys.executable, exc)) from exc


def options(base=None, **values):
    """An :class:`Options` (``base`` or the defaults, with ``values`` replacing fields),
    checked: an unknown name or a value outside its domain raises InputError naming it."""
    known = {f.name for f in dataclasses.fields(Options)} - {"context"}
    unknown = sorted(set(values) - known)
    if unknown:
        raise InputError("unknown option%s %s (expected some of %s)"
                         % ("s" if len(unknown) > 1 else "", ", ".join(unknown),
                            ", ".join(sorted(known))))
    return dataclasses.replace(base or Options(), **values).validate()


_options = options      # compensate's argument of the same name hides it there


def read_measurements(path, units="mm", fmt="auto", sample=None, deviation_units=None):
    """Read a measurement file of any supported format (README "Measurement files").

    Parameters
    ----------
    path : str or os.PathLike
    units : {'mm', 'um', 'in'}
        Unit of values without a unit of their own.
    fmt : str
        ``auto`` (detected) or one of :data:`surfcomp.io.readers.FORMATS`.
    sample : int or str, optional
        Which measured part of a QIF file holding several (default the first).
    deviation_units : {'mm', 'um', 'in'}, optional
        Unit of a deviation column without a unit of its own, when not ``units``.

    Returns
    -------
    MeasurementSet
        Lengths in mm; ``warnings`` holds what the reader noticed.
    """
    from .io.readers import read_any

    return read_any(os.fspath(path), units, fmt, sample, deviation_units=deviation_units)


def load_nominal(path, face=None, object=None):
    """Load the nominal face from a STEP/IGES/BREP file or a FreeCAD document. Needs FreeCAD.

    Parameters
    ----------
    path : str or os.PathLike
    face : str, optional
        ``FaceN`` of the shape (default: its only B-spline face).
    object : str, optional
        The document object (Name or Label) of an ``.FCStd`` (default: the only object with
        B-spline faces at the top of the document).

    Returns
    -------
    surfcomp.app.nominal.Nominal
        The face, its B-spline ``surface`` (core arrays), ``outward`` (+1 or -1: the side
        its outward normal points to) and the whole ``shape`` it belongs to.
    """
    require_freecad("surfcomp.load_nominal")
    from .app.nominal import load_nominal as load

    return load(os.fspath(path), face, object)


@dataclass
class Result:
    """What :func:`compensate` returns: the nominal, the measurement set, the options and
    the core :class:`Compensation`.

    ``statistics`` (name -> :class:`~surfcomp.core.compensation.deviations.Statistics`, mm:
    deviation, determined, random, correction), ``corrected`` (the corrected surface's core arrays,
    None for ``build=False``) and ``warnings`` are the compensation's.
    """

    nominal: object
    measurements: MeasurementSet
    options: Options
    compensation: Compensation

    @property
    def statistics(self):
        return self.compensation.statistics

    @property
    def corrected(self):
        return self.compensation.corrected

    @property
    def warnings(self):
        return self.compensation.prepared.warnings

    def per_point(self, name):
        """``deviation``, ``determined``, ``random`` or ``delta`` (the intended correction)
        at every measured point, in file order (mm)."""
        return self.compensation.per_point(name)

    def corrected_points(self):
        """The corrected points at the measured points (mm), (N, 3) in file order."""
        return self.compensation.corrected_points()


def compensate(nominal, measurements, options=None, build=True, progress=None, **values):
    """Deviations, their filtered components, the intended correction and (``build``) the
    corrected surface of ``measurements`` against ``nominal``.

    Parameters
    ----------
    nominal : surfcomp.app.nominal.Nominal
        From :func:`load_nominal`; any object with a core ``surface`` and its ``outward``
        sign will do (numpy and scipy only then).
    measurements : MeasurementSet
        From :func:`read_measurements`.
    options : Options, optional
        Default: the command line's defaults.
    build : bool
        False: inspection only (no corrected surface), as ``surfcomp inspect``.
    progress : callable, optional
        ``progress(fraction, message)``.
    **values
        Options replacing those of ``options`` (``method="mirror", stock=0.2``).

    Returns
    -------
    Result
    """
    opts = _options(options, **values)
    prepared = _prepare(nominal.surface, nominal.outward, measurements, opts,
                        progress=_part(progress, 0.0, 0.3))
    if getattr(nominal, "bspline_face", None) is not None:    # a loaded face: its trim
        from .app.nominal import face_warnings

        prepared.warnings.extend(face_warnings(nominal, prepared))
    comp = _compensate(nominal.surface, nominal.outward, prepared, opts, build=build,
                       progress=_part(progress, 0.3, 1.0))
    return Result(nominal, measurements, opts, comp)


def _part(progress, lo, hi):
    from .core.progress import sub

    return sub(progress, lo, hi)


def _built(result, what):
    if not isinstance(result, Result):
        raise InputError("%s takes the result of surfcomp.compensate, not %s"
                         % (what, type(result).__name__))
    if result.corrected is None:
        raise InputError("%s: the result has no corrected surface (compensate it with "
                         "build=True)" % what)
    if getattr(result.nominal, "bspline_face", None) is None:
        raise InputError("%s: the result's nominal is no loaded face (use "
                         "surfcomp.load_nominal)" % what)


def write_face(result, path):
    """Write the corrected face alone (the nominal face's boundary on the corrected
    surface, its orientation) as STEP, IGES or BREP by the extension. Needs FreeCAD.

    Returns the path. Nothing is written when anything fails, and no output replaces an
    input (the nominal, the measurement file)."""
    return _write_shape(result, path, "face", "surfcomp.write_face")


def write_solid(result, path):
    """Write the nominal's whole shape with the face replaced by the corrected face and its
    neighbours re-trimmed (same faces in the same order), as STEP, IGES or BREP; a lone
    face gives the face. Needs FreeCAD. Returns the path."""
    return _write_shape(result, path, "solid", "surfcomp.write_solid")


def _write_shape(result, path, kind, what):
    _built(result, what)
    require_freecad(what)
    from .app.file_route import cad_format, write_face
    from .app.shapes import corrected_shape
    from .io.atomic import Transaction, check_outputs

    path = os.fspath(path)
    cad_format(path, "path")
    outputs, inputs = [("path", path)], _inputs(result)
    check_outputs(outputs, inputs)
    nominal = result.nominal
    output = corrected_shape(nominal, result.corrected, kind, nominal.face_name)
    name = os.path.splitext(os.path.basename(path))[0]
    with Transaction(outputs, inputs) as tx:
        tx.write(path, lambda tmp: write_face(tmp, output.shape, output, name))
        tx.commit()
    return path


def _inputs(result):
    return [(label, p) for label, p in (("nominal", result.nominal.source),
                                        ("measurements", result.measurements.source))
            if p and os.path.isfile(p)]


def write_document(result, path, output="solid"):
    """Write a FreeCAD document (``.FCStd``) holding the nominal shape, the measurement
    and a compensation object with ``result``'s options, recomputed: the document route
    of the GUI, editable there. ``output``: ``solid`` (the nominal's shape with the face
    replaced) or ``face``. Opening it needs surfcomp installed as a FreeCAD addon
    (``tools/install.sh``). Needs FreeCAD. Returns the path."""
    _built(result, "surfcomp.write_document")
    require_freecad("surfcomp.write_document")
    from .app.result_document import write_result_document

    return write_result_document(result, os.fspath(path), output, _inputs(result))

