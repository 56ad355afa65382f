# SPDX-License-Identifier: LGPL-2.1-or-later
"""The linear units of a QIF 3.0 document (no FreeCAD): the primary unit of its
FileUnits, the other units ``linearUnit`` attributes can name, and the factor to mm of
every value (:mod:`surfcomp.io.qif` reads the document)."""

from .units import unit_factor

#: QIF unit names (lower case) -> factor to mm, for LinearUnits without UnitConversion
_UNIT_NAMES = {
    "mm": 1.0, "millimeter": 1.0, "millimetre": 1.0, "millimeters": 1.0, "millimetres": 1.0,
    "in": 25.4, "inch": 25.4, "inches": 25.4,
    "m": 1000.0, "meter": 1000.0, "metre": 1000.0, "meters": 1000.0, "metres": 1000.0,
    "cm": 10.0, "centimeter": 10.0, "centimetre": 10.0,
    "um": 1e-3, "µm": 1e-3, "micrometer": 1e-3, "micrometre": 1e-3, "micron": 1e-3,
    "ft": 304.8, "foot": 304.8, "feet": 304.8,
}
#: factor to mm -> the short name used in ``MeasurementSet.units``
_SHORT = {1.0: "mm", 25.4: "in", 1000.0: "m", 10.0: "cm", 1e-3: "um", 304.8: "ft"}


# ------------------------------------------------------------------------------- units

class FileUnits:
    """Linear units of a document: the primary one and those ``linearUnit`` can name."""

    def __init__(self, doc, units):
        self.doc = doc
        self.named = {}
        lu = doc.find(doc.root, "q:FileUnits/q:PrimaryUnits/q:LinearUnit")
        if lu is None:
            if units is None:
                self.primary, self.name = 1000.0, "m"
                doc.warn("the file has no FileUnits/PrimaryUnits/LinearUnit: lengths are read "
                         "in metres (the QIF default); give units= if they are not")
            else:
                self.primary = unit_factor(units)
                self.name = next((s for f, s in _SHORT.items() if f == self.primary), units)
                doc.warn("the file has no FileUnits/PrimaryUnits/LinearUnit (the QIF default "
                         "is metres): lengths are read in %s as units=%r says"
                         % (self.name, units))
        else:
            self.primary, self.name = self._factor(lu)
            if units is not None and unit_factor(units) != self.primary:
                doc.warn("the file states its units (%s); units=%r is not used"
                         % (self.name, units))
        for el in doc.findall(doc.root, "q:FileUnits/q:OtherUnits/q:LinearUnit") + (
                [lu] if lu is not None else []):
            name_el = doc.find(el, "q:UnitName")
            if name_el is not None and name_el.text:
                self.named[name_el.text.strip()] = self._factor(el)[0]

    def _factor(self, lu):
        """(factor to mm, short name) of a LinearUnit element."""
        doc = self.doc
        name_el = doc.find(lu, "q:UnitName")
        name = (name_el.text or "").strip() if name_el is not None else ""
        conv = doc.find(lu, "q:UnitConversion")
        by_name = _UNIT_NAMES.get(name.lower())
        if conv is not None:
            fac = doc.find(conv, "q:Factor")
            if fac is None:
                raise doc.error("<UnitConversion> of the linear unit %r has no <Factor>; "
                                "expected the factor to metres" % name, conv)
            factor = float(doc.numbers(fac, 1, "the factor to metres")[0]) * 1000.0
            off = doc.find(conv, "q:Offset")
            if off is not None and doc.numbers(off, 1, "0 for a length unit")[0] != 0.0:
                raise doc.error("the linear unit %r has a non-zero <Offset>; expected none for "
                                "a length unit" % name, off)
            if factor <= 0.0:
                raise doc.error("the linear unit %r has the factor %g to metres; expected a "
                                "positive factor" % (name, factor / 1000.0), fac)
            if by_name is not None and abs(factor - by_name) > 1e-9 * by_name:
                raise doc.error("the linear unit is named %r but its <Factor> is %g m; "
                                "expected %g m" % (name, factor / 1000.0, by_name / 1000.0), fac)
        elif by_name is not None:
            factor = by_name
        else:
            raise doc.error("the linear unit %r is not known and has no <UnitConversion>; "
                            "expected mm, inch, m or a UnitConversion/Factor to metres" % name, lu)
        short = next((s for f, s in _SHORT.items() if abs(f - factor) <= 1e-9 * f), name)
        return factor, short

    def of(self, el):
        """Factor to mm for the value(s) in element ``el``."""
        unit = el.get("linearUnit")
        if unit is None:
            return self.primary
        if unit not in self.named:
            raise self.doc.error("linearUnit=%r names no LinearUnit of FileUnits (known: %s)"
                                 % (unit, ", ".join(sorted(self.named)) or "none"), el)
        return self.named[unit]
