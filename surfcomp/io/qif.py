# SPDX-License-Identifier: LGPL-2.1-or-later
"""QIF 3.0 measurement results (ISO 23952): surface points with nominal, normal, actual
and the file's own deviations (no FreeCAD).

What is read
------------
A QIF results document links its data by ids::

    MeasurementResults/MeasuredFeatures/PointFeatureMeasurement  (actual <Location>)
        --FeatureItemId-->     Features/FeatureItems/PointFeatureItem      (<FeatureName>)
        --FeatureNominalId-->  Features/FeatureNominals/PointFeatureNominal
                                                     (nominal <Location>, <Normal>)
    MeasurementResults/MeasuredCharacteristics/CharacteristicMeasurements/
        PointProfileCharacteristicMeasurement  --FeatureMeasurementIds--> the measurement
                                                     (<Value>: signed deviation)

A surface point is a measured feature whose nominal is a ``PointFeatureNominal`` with a
``Normal``. Edge points (``EdgePointFeature*``: a point on a trimmed edge, its deviation
measured in the sheet plane), holes (``CircleFeature*``) and other features are not
surface points: they are skipped and counted in a warning, as are point nominals
without a normal.

The deviation is the point-profile ``Value`` the file carries (signed, positive on the
side the nominal normal points to). It is cross-checked against
``(actual - nominal) . normal`` (the same convention as
:func:`surfcomp.core.compensation.deviations.signed_deviation`); differences above ``deviation_tol``
are warnings, and values of the opposite sign of their points on half the points or more
are refused, as a table's dev column is. A point without a point-profile value gets the
computed deviation (a warning says so). When several point-profile values refer to one
measured point (the CheckMate sample files carry the deviation and a second value 0 for
every point) the first in file order is used, with a warning. A nominal point measured
twice is refused, as in a table.

Several parts
-------------
A file may hold several ``MeasurementResults`` (one per measured part, e.g. the six
samples of ``SheetMetal_QIF_Results_6_samples.QIF``). ``sample`` chooses one: an ``int``
is a 0-based index in file order; a ``str`` is the part's serial number (from
``ActualComponent/SerialNumber``) or the ``MeasurementResults`` id, and a string of
digits that is neither is taken as an index. By default the first is read and a
warning lists the others. :func:`qif_samples` lists them.

Units
-----
Lengths are in the ``FileUnits/PrimaryUnits/LinearUnit`` of the file, or in the unit an
element's ``linearUnit`` attribute names (a LinearUnit of ``PrimaryUnits`` or
``OtherUnits``); a unit is identified by its ``UnitConversion/Factor`` (to metres) or,
without one, by its name (mm, inch, ...). A file without ``FileUnits`` is in metres
(the QIF default, Units.xsd) unless ``units`` is given (a warning says which unit was
used); when the file has FileUnits, ``units`` is not used. Everything returned is in mm.

Source lines
------------
``MeasurementSet.lines`` holds the line of each point's ``<PointFeatureMeasurement>``
start tag; errors name the line (and for XML syntax errors the column) of the element
concerned.
"""

import collections
import hashlib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from xml.parsers import expat

import numpy as np

from ..errors import InputError, MeasurementFileError, note
from .files import clip, read_bytes
from .measurement_set import (
    DEV_CHECK_TOL,
    MAX_POINT_WARNINGS,
    NORMAL_LENGTH_TOL,
    NORMAL_ZERO,
    MeasurementSet,
    check_coordinates,
    check_duplicates,
)
from .qif_units import FileUnits

#: namespace URIs of QIF documents start with this (QIF 3: ``.../qif3``)
QIF_NAMESPACE_PREFIX = "http://qifstandards.org/xsd/qif"

_SURFACE_POINT = "PointFeatureNominal"


@dataclass(frozen=True)
class QifSample:
    """One ``MeasurementResults`` block of a QIF file (one measured part)."""

    index: int          #: 0-based position in the file
    id: str             #: the MeasurementResults id
    serial: str         #: SerialNumber of its ActualComponent, or None
    line: int           #: line of the MeasurementResults start tag
    features: int       #: number of measured features it holds

    def describe(self):
        return "%d: %s (MeasurementResults id %s, line %d)" % (
            self.index, self.serial or "no serial number", self.id, self.line)


def _local(tag):
    """Local name of an ElementTree tag ``{ns}Name``."""
    return tag.rpartition("}")[2]


class _Doc:
    """A parsed QIF document with the source line of every element."""

    def __init__(self, path, data):
        self.source = str(path)
        self.line_of = {}
        self.root = self._parse(data)
        tag = self.root.tag
        ns = tag[1:tag.index("}")] if tag.startswith("{") else ""
        if _local(tag) != "QIFDocument":
            raise self.error("the root element is <%s>; expected <QIFDocument> (a QIF 3.0 "
                             "document)" % _local(tag), self.root)
        if not ns.startswith(QIF_NAMESPACE_PREFIX):
            raise self.error("<QIFDocument> is in the namespace %r; expected %s3"
                             % (ns, QIF_NAMESPACE_PREFIX), self.root)
        self.ns = {"q": ns}
        self.warnings = []
        version = self.root.get("versionQIF")
        if version is not None and not version.startswith("3"):
            self.warn("versionQIF is %r; this reader follows QIF 3.0" % version, self.root)

    # -- parsing ----------------------------------------------------------------------------

    def _parse(self, data):
        """ElementTree of ``data`` built through expat, recording each element's line."""
        builder = ET.TreeBuilder()
        parser = expat.ParserCreate(namespace_separator="}")
        line_of = self.line_of

        def name(raw):
            return "{" + raw if "}" in raw else raw

        def start(tag, attrs):
            el = builder.start(name(tag), {name(k): v for k, v in attrs.items()})
            line_of[el] = parser.CurrentLineNumber

        def entity(*_args):
            raise MeasurementFileError("the document declares entities; QIF files declare "
                                       "none (refused)", file=self.source,
                                       line=parser.CurrentLineNumber)

        parser.StartElementHandler = start
        parser.EndElementHandler = lambda tag: builder.end(name(tag))
        parser.CharacterDataHandler = builder.data
        parser.EntityDeclHandler = entity
        parser.buffer_text = True
        try:
            parser.Parse(data, True)
        except expat.ExpatError as exc:
            raise MeasurementFileError("not well-formed XML: %s (expected a QIF 3.0 XML "
                                       "document)" % expat.ErrorString(exc.code),
                                       file=self.source, line=exc.lineno,
                                       column=exc.offset + 1) from exc
        except (LookupError, ValueError) as exc:  # the declared encoding cannot be decoded
            raise MeasurementFileError("the XML declaration names an encoding that cannot be "
                                       "read (%s; expected UTF-8)" % exc, file=self.source,
                                       line=1) from None
        return builder.close()

    # -- helpers ----------------------------------------------------------------------------

    def line(self, el):
        return self.line_of.get(el)

    def error(self, message, el=None):
        return MeasurementFileError(message, file=self.source,
                                    line=None if el is None else self.line(el))

    def warn(self, message, el=None):
        line = None if el is None else self.line(el)
        if line is None:
            self.warnings.append("%s: " % self.source + message)     # (a Note stays one)
        else:
            self.warnings.append("%s:%d: " % (self.source, line) + message)

    def find(self, el, path):
        return el.find(path, self.ns)

    def findall(self, el, path):
        return el.findall(path, self.ns)

    def text(self, el, child, what):
        """Stripped text of the required child element ``child`` of ``el``."""
        c = self.find(el, "q:" + child)
        if c is None or c.text is None or not c.text.strip():
            raise self.error("<%s id=%r> has no %s; expected <%s>%s</%s>"
                             % (_local(el.tag), el.get("id"), child, child, what, child), el)
        return c.text.strip(), c

    def numbers(self, el, count, what):
        """``count`` floats from the text of ``el`` (finite, decimal)."""
        toks = (el.text or "").split()
        if len(toks) != count:
            raise self.error("<%s> holds %d numbers; expected %d (%s)"
                             % (_local(el.tag), len(toks), count, what), el)
        try:
            values = np.array([float(t) for t in toks])
        except ValueError:
            bad = next(t for t in toks if not _is_float(t))
            raise self.error("<%s> holds %r, which is not a number; expected %s"
                             % (_local(el.tag), clip(bad), what), el) from None
        if not np.all(np.isfinite(values)):
            raise self.error("<%s> holds %r; expected finite numbers (%s)"
                             % (_local(el.tag), clip(el.text.strip()), what), el)
        return values


def _is_float(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


# ------------------------------------------------------------------------------- samples

def _read(path):
    data = read_bytes(path)
    if not data.strip():
        raise MeasurementFileError("the file is empty; expected a QIF 3.0 XML document",
                                   file=str(path))
    return data


def _samples(doc):
    serial_of = {}
    for ac in doc.root.iter("{%s}ActualComponent" % doc.ns["q"]):
        sn = doc.find(ac, "q:SerialNumber")
        if ac.get("id") is not None and sn is not None and sn.text:
            serial_of[ac.get("id")] = sn.text.strip()
    out = []
    blocks = doc.findall(doc.root, "q:Results/q:MeasurementResultsSet/q:MeasurementResults")
    for k, mr in enumerate(blocks):
        serial = None
        for ref in doc.findall(mr, "q:ActualComponentIds/q:Id"):
            serial = serial_of.get((ref.text or "").strip())
            if serial is not None:
                break
        mf = doc.find(mr, "q:MeasuredFeatures")
        out.append(QifSample(index=k, id=mr.get("id"), serial=serial, line=doc.line(mr),
                             features=0 if mf is None else len(mf)))
    return blocks, out


def qif_samples(path):
    """List the measured parts (``MeasurementResults``) of a QIF results file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    list of QifSample
        In file order; empty for a file without results (a plan).
    """
    doc = _Doc(path, _read(path))
    return _samples(doc)[1]


def _choose(doc, blocks, samples, sample):
    listing = "; ".join(s.describe() for s in samples)
    if sample is None:
        if len(samples) > 1:
            doc.warn(note("the file holds %d measured parts (MeasurementResults): %s; the first "
                          "is read, choose another with " % (len(samples), listing),
                          ("sample",)))
        return 0
    if isinstance(sample, (bool, np.bool_)) or not isinstance(sample, (int, np.integer, str)):
        raise InputError("sample=%r: expected a 0-based index, a serial number or a "
                         "MeasurementResults id" % (sample,), file=doc.source)
    if isinstance(sample, str):
        for s in samples:
            if sample in (s.serial, s.id):
                return s.index
        if not sample.strip().isdigit():
            raise MeasurementFileError("no measured part has the serial number or "
                                       "MeasurementResults id %r; the file holds: %s"
                                       % (sample, listing), file=doc.source)
        sample = int(sample)
    if not 0 <= sample < len(samples):
        raise MeasurementFileError("sample %d does not exist: the file holds %d measured part(s) "
                                   "(0-based index): %s" % (sample, len(samples), listing),
                                   file=doc.source)
    return int(sample)


# ------------------------------------------------------------------------------- reader

def read_qif(path, sample=None, units=None, deviation_tol=DEV_CHECK_TOL):
    """Read the surface points of one measured part from a QIF 3.0 results file.

    Parameters
    ----------
    path : str or os.PathLike
    sample : int or str, optional
        Which ``MeasurementResults``: 0-based index, serial number or MeasurementResults
        id (see the module docstring). Default: the first (a warning lists the others).
    units : str, optional
        Length unit for a file without ``FileUnits`` (default metres, the QIF default;
        a warning says which unit was used). The file's ``FileUnits`` win.
    deviation_tol : float
        Largest accepted difference (mm) between the file's point-profile value and
        ``(actual - nominal) . normal`` before a warning (default
        :data:`surfcomp.io.measurements.DEV_CHECK_TOL`, 1 um).

    Returns
    -------
    MeasurementSet
        ``nominal`` (N, 3) mm, ``measured`` (N, 3) mm, ``normal`` (N, 3) unit nominal
        normals, ``deviation`` (N,) mm (the file's values), ``ids`` the FeatureNames,
        ``lines`` the line of each ``<PointFeatureMeasurement>``, ``units`` the file's
        length unit. ``row``/``col`` are None.

    Raises
    ------
    MeasurementFileError
        Not XML (line and column from the parser), not a QIF document, no results, a
        requested sample that does not exist, ids that resolve to nothing (named), no
        surface points, malformed numbers or units.
    """
    data = _read(path)
    doc = _Doc(path, data)
    ufac = FileUnits(doc, units)
    blocks, samples = _samples(doc)
    if not blocks:
        noms = doc.find(doc.root, "q:Features/q:FeatureNominals")
        raise doc.error("the file holds no <MeasurementResults> (%d feature nominals: a QIF "
                        "plan?); expected QIF measurement results"
                        % (0 if noms is None else len(noms)), doc.root)
    k = _choose(doc, blocks, samples, sample)
    mr = blocks[k]

    with np.errstate(over="ignore"):    # overflowing values are refused by the checks
        pts = _surface_points(doc, mr, ufac)
        nominal, measured, normal = (np.array(pts[key]) for key in ("nom", "act", "nrm"))
        ids, lines = pts["ids"], pts["lines"]
        check_coordinates(nominal, lines, doc.source)
        check_coordinates(measured, lines, doc.source)
        check_duplicates(nominal, lines, doc.source)
        computed = np.einsum("ij,ij->i", measured - nominal, normal)
        deviation, from_file = _file_deviations(doc, mr, ufac, pts, computed, deviation_tol)
    check_coordinates(np.asarray(deviation, dtype=float)[:, None], lines, doc.source,
                      limit=np.inf, what="deviation")

    columns = {}
    for r in ("x_nom", "y_nom", "z_nom"):
        columns[r] = "PointFeatureNominal/Location"
    for r in ("x_meas", "y_meas", "z_meas"):
        columns[r] = "PointFeatureMeasurement/Location"
    for r in "ijk":
        columns[r] = "PointFeatureNominal/Normal"
    if from_file.any():
        columns["dev"] = "PointProfileCharacteristicMeasurement/Value"
    columns["id"] = "PointFeatureItem/FeatureName"
    return MeasurementSet(
        nominal=nominal, measured=measured, normal=normal, deviation=deviation,
        row=None, col=None, ids=ids, lines=np.array(lines, dtype=np.int64),
        source=doc.source, sha256=hashlib.sha256(data).hexdigest(), units=ufac.name,
        columns=columns, ignored_columns=[], warnings=doc.warnings, separator=" ",
        decimal_comma=False)


def _surface_point(doc, fm, items, nominals, ufac, skipped, no_normal):
    """One measured feature: ``(nominal, actual, normal, name)`` of a surface point, or None
    (counted in ``skipped`` / ``no_normal``)."""
    fid = fm.get("id")
    item_id, _ = doc.text(fm, "FeatureItemId", "the id of a feature item")
    item = items.get(item_id)
    if item is None:
        raise doc.error("<%s id=%r> refers to FeatureItemId %s, which is no feature item "
                        "of the file; expected an id under Features/FeatureItems"
                        % (_local(fm.tag), fid, item_id), fm)
    nominal_id, _ = doc.text(item, "FeatureNominalId", "the id of a feature nominal")
    nominal = nominals.get(nominal_id)
    if nominal is None:
        raise doc.error("<%s id=%r> refers to FeatureNominalId %s, which is no feature "
                        "nominal of the file; expected an id under Features/FeatureNominals"
                        % (_local(item.tag), item.get("id"), nominal_id), item)
    kind = _local(nominal.tag)
    if kind != _SURFACE_POINT:
        skipped[kind.replace("FeatureNominal", "")] += 1
        return None
    normal_el = doc.find(nominal, "q:Normal")
    name_el = doc.find(item, "q:FeatureName")
    name = name_el.text.strip() if name_el is not None and name_el.text else \
        "feature item %s" % item_id
    if normal_el is None:
        no_normal.append(name)
        return None
    _, nloc = doc.text(nominal, "Location", "x y z")
    _, aloc = doc.text(fm, "Location", "x y z")
    n = doc.numbers(normal_el, 3, "the unit normal i j k")
    length = float(np.linalg.norm(n))
    if length < NORMAL_ZERO:
        raise doc.error("the <Normal> of <PointFeatureNominal id=%r> is zero; expected a "
                        "unit vector" % nominal_id, normal_el)
    if not np.isfinite(length):
        raise doc.error("the <Normal> of <PointFeatureNominal id=%r> is too long to be "
                        "normalised; expected a unit vector" % nominal_id, normal_el)
    if abs(length - 1.0) > NORMAL_LENGTH_TOL:
        doc.warn("the normal of %s has length %.6g; used normalised" % (name, length),
                 normal_el)
    return (doc.numbers(nloc, 3, "nominal x y z") * ufac.of(nloc),
            doc.numbers(aloc, 3, "actual x y z") * ufac.of(aloc), n / length, name)


def _surface_points(doc, mr, ufac):
    """The surface points of one ``MeasurementResults``: lists ``nom``, ``act``, ``nrm``,
    ``ids``, ``lines``, ``meas_ids``."""
    nominals = _by_id(doc, "q:Features/q:FeatureNominals")
    items = _by_id(doc, "q:Features/q:FeatureItems")
    mf = doc.find(mr, "q:MeasuredFeatures")
    if mf is None or len(mf) == 0:
        raise doc.error("MeasurementResults id %s holds no measured features; expected "
                        "<MeasuredFeatures> with surface points" % mr.get("id"), mr)
    pts = {key: [] for key in ("nom", "act", "nrm", "ids", "lines", "meas_ids")}
    skipped = collections.Counter()
    no_normal = []
    for fm in mf:
        got = _surface_point(doc, fm, items, nominals, ufac, skipped, no_normal)
        if got is None:
            continue
        for key, value in zip(("nom", "act", "nrm", "ids"), got):
            pts[key].append(value)
        pts["lines"].append(doc.line(fm))
        pts["meas_ids"].append(fm.get("id"))
    skipped_text = ", ".join("%d %s" % (c, t) for t, c in sorted(skipped.items()))
    if skipped:
        doc.warn("%d measured feature(s) are not surface points and were skipped: %s"
                 % (sum(skipped.values()), skipped_text), mr)
    if no_normal:
        doc.warn("%d point feature(s) have no nominal <Normal> and were skipped: %s"
                 % (len(no_normal), ", ".join(no_normal)), mr)
    if not pts["nom"]:
        raise doc.error("MeasurementResults id %s holds no surface points (point features "
                        "with a nominal normal); skipped: %s"
                        % (mr.get("id"), skipped_text or "none"), mr)
    return pts


def _file_deviations(doc, mr, ufac, pts, computed, deviation_tol):
    """The file's point-profile values where given (else ``computed``), checked against
    ``computed``; returns ``(deviation, from_file)``."""
    ids, lines = pts["ids"], pts["lines"]
    values = _profile_values(doc, mr, ufac)
    deviation = computed.copy()
    from_file = np.zeros(len(ids), dtype=bool)
    several = []
    for p, fid in enumerate(pts["meas_ids"]):
        vals = values.get(fid)
        if vals:
            deviation[p] = vals[0][0]
            from_file[p] = True
            if len(vals) > 1:
                several.append((p, vals))
    if several:
        p, vals = several[0]
        doc.warn("%d point(s) carry more than one PointProfileCharacteristicMeasurement; the "
                 "first in file order is used (e.g. %s: %s used, %s not)"
                 % (len(several), ids[p], "%.9g" % (vals[0][0]),
                    ", ".join("%.9g" % v for v, _ in vals[1:])), mr)
    missing = np.flatnonzero(~from_file)
    if missing.size:
        doc.warn("%d point(s) carry no point-profile value; their deviation is (actual - "
                 "nominal) . normal: %s" % (missing.size, ", ".join(ids[p] for p in missing)),
                 mr)
    diff = np.abs(deviation - computed)
    bad = np.flatnonzero(from_file & (diff > deviation_tol))
    if bad.size and 2 * bad.size >= np.count_nonzero(from_file) and np.all(
            np.abs(deviation[bad] + computed[bad]) <= deviation_tol):
        # as for a table's dev column: whichever is right, the correction would go the
        # wrong way for one of them
        p = int(bad[0])
        raise MeasurementFileError(
            "%s: the file's deviation %.6f mm has the opposite sign of (actual - nominal) . "
            "normal = %.6f mm, as on %d of the %d point-profile values (expected them to agree "
            "within %g um: do the values measure along the inward normal? Correct the values "
            "or the nominal normals)" % (ids[p], deviation[p], computed[p], bad.size,
                                        np.count_nonzero(from_file), deviation_tol * 1e3),
            file=doc.source, line=lines[p])
    for p in bad[:MAX_POINT_WARNINGS]:
        doc.warnings.append("%s:%d: %s: the file's deviation %.6f mm differs from (actual - "
                            "nominal) . normal = %.6f mm by %.1f um (expected at most %g um)"
                            % (doc.source, lines[p], ids[p], deviation[p], computed[p],
                               diff[p] * 1e3, deviation_tol * 1e3))
    if bad.size > MAX_POINT_WARNINGS:
        doc.warn("%d more deviations differ from (actual - nominal) . normal by more than %g um"
                 % (bad.size - MAX_POINT_WARNINGS, deviation_tol * 1e3))
    return deviation, from_file


def _by_id(doc, path):
    """Children with an ``id`` of the container at ``path`` -> {id: element}."""
    container = doc.find(doc.root, path)
    if container is None:
        raise doc.error("the file has no %s; expected the feature definitions of the "
                        "measured points" % path.replace("q:", ""), doc.root)
    return {el.get("id"): el for el in container if el.get("id") is not None}


def _profile_values(doc, mr, ufac):
    """Point-profile values of one MeasurementResults: {feature measurement id: [(mm, el)]}.

    A characteristic measurement names its feature measurement(s) in
    ``FeatureMeasurementIds``; without those the link goes through its characteristic
    item's ``FeatureItemIds`` to the feature measurement of that item in ``mr``.
    """
    out = collections.defaultdict(list)
    cms = doc.find(mr, "q:MeasuredCharacteristics/q:CharacteristicMeasurements")
    if cms is None:
        return out
    char_items = {}
    ci = doc.find(doc.root, "q:Characteristics/q:CharacteristicItems")
    if ci is not None:
        char_items = {el.get("id"): el for el in ci}
    meas_of_item = {}
    mf = doc.find(mr, "q:MeasuredFeatures")
    measured_ids = set()
    for fm in (mf if mf is not None else []):
        measured_ids.add(fm.get("id"))
        item = doc.find(fm, "q:FeatureItemId")
        if item is not None and item.text:
            meas_of_item[item.text.strip()] = fm.get("id")
    for cm in cms:
        if _local(cm.tag) != "PointProfileCharacteristicMeasurement":
            continue
        value_el = doc.find(cm, "q:Value")
        if value_el is None:
            continue
        value = doc.numbers(value_el, 1, "the signed deviation")[0] * ufac.of(value_el)
        refs = [(r.text or "").strip() for r in doc.findall(cm, "q:FeatureMeasurementIds/q:Id")]
        if not refs:
            cid, _ = doc.text(cm, "CharacteristicItemId", "the id of a characteristic item")
            item = char_items.get(cid)
            if item is None:
                raise doc.error("<PointProfileCharacteristicMeasurement id=%r> refers to "
                                "CharacteristicItemId %s, which is no characteristic item of "
                                "the file" % (cm.get("id"), cid), cm)
            for fi in doc.findall(item, "q:FeatureItemIds/q:Id"):
                fid = meas_of_item.get((fi.text or "").strip())
                if fid is None:
                    raise doc.error("<PointProfileCharacteristicMeasurement id=%r> names no "
                                    "FeatureMeasurementIds and its characteristic item %s "
                                    "refers to feature item %s, which is not measured in "
                                    "MeasurementResults id %s"
                                    % (cm.get("id"), cid, (fi.text or "").strip(),
                                       mr.get("id")), cm)
                refs.append(fid)
        for ref in refs:
            if ref not in measured_ids:
                raise doc.error("<PointProfileCharacteristicMeasurement id=%r> refers to "
                                "feature measurement %s, which is not in MeasurementResults "
                                "id %s" % (cm.get("id"), ref, mr.get("id")), cm)
            out[ref].append((value, value_el))
    return out
