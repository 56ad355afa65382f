# SPDX-License-Identifier: LGPL-2.1-or-later
"""View providers of the surfcomp document objects (FreeCAD GUI only).

``ViewProviderCompensation`` adds the display mode ``Map``: the chosen quantity
(raw deviation, determined or random component, correction, predicted residual) drawn
on the nominal face as a colour map with markers, labels and a legend. Range, scheme,
tolerance band and unit are properties of the view object: changing them recolours
without recomputing the document. State lives in properties; the proxy only caches
the mesh and values (rebuilt whenever the object's Shape changes).

The module path ``surfcomp.gui.viewproviders`` is stored in documents: keep it.
"""

import FreeCAD
import numpy as np
from PySide import QtCore
from PySide.QtCore import QT_TRANSLATE_NOOP

from .. import paths
from ..app import features, reports
from ..app.mapmesh import map_data, map_mesh, mesh_key  # noqa: F401  (scripts, bench/)
from ..core import colormap
from ..errors import SurfcompError
from . import cover, map_style, prefs
from .mapscene import MapScene

#: 2: short property names that fit the property view (RENAMED)
VERSION = 2
#: view properties renamed in version 2: old name -> new name (moved on restore)
RENAMED = {"ToleranceBand": "TolBand", "ToleranceLower": "TolLow", "ToleranceUpper": "TolHigh",
           "LegendUnit": "Unit", "ShowLegend": "Legend", "ShowPoints": "Points",
           "ShowLabels": "Labels"}

QUANTITIES = reports.QUANTITIES  # the quantities a map shows (the reports')
TITLES = {"deviation": "Deviation", "determined": "Determined component",
          "random": "Random component", "correction": "Correction",
          "increment": "Correction of this round", "residual": "Predicted residual"}
#: the sign convention under the title of the maps whose sign is not a deviation's
NOTES = {"correction": "+ = material removed (the face moves in by it)",
         "increment": "+ = material removed (the face moves in by it)",
         "deviation": "+ = material left", "residual": "left of the systematic error"}
#: view properties whose change only recolours the map
STYLE_PROPERTIES = ("Scheme", "AutoRange", "RangeMin", "RangeMax", "TolBand",
                    "TolLow", "TolHigh", "Unit", "Points",
                    "Labels", "Legend", "Stepped", "Shared", "WarnBand",
                    "Histogram")

#: compensation properties whose change invalidates the drawn map
RESULT_PROPERTIES = ("Shape", "GridRows", "GridCols", "U", "V", "Nodes", "Deviation",
                     "Determined", "Random", "Increment", "Correction", "Version")

_G = "Colour map"
# (type, name, tooltip, default)
MAP_PROPERTIES = (
    ("App::PropertyEnumeration", "Map",
     QT_TRANSLATE_NOOP("App::Property", "Quantity drawn in the Map display mode"),
     list(QUANTITIES)),
    ("App::PropertyEnumeration", "Scheme",
     QT_TRANSLATE_NOOP("App::Property", "Colour scheme"),
     list(colormap.SCHEMES)),
    ("App::PropertyBool", "AutoRange",
     QT_TRANSLATE_NOOP("App::Property", "Symmetric range from the largest absolute value (off: "
                                        "RangeMin .. RangeMax)"),
     True),
    ("App::PropertyDistance", "RangeMin",
     QT_TRANSLATE_NOOP("App::Property", "Lower end of the colour range (AutoRange off)"),
     -0.05),
    ("App::PropertyDistance", "RangeMax",
     QT_TRANSLATE_NOOP("App::Property", "Upper end of the colour range (AutoRange off)"),
     0.05),
    ("App::PropertyBool", "TolBand",
     QT_TRANSLATE_NOOP("App::Property", "Tolerance band mode: in tolerance one colour, below and "
                                        "above their own"),
     False),
    ("App::PropertyDistance", "TolLow",
     QT_TRANSLATE_NOOP("App::Property", "Lower limit of the tolerance band"),
     -0.01),
    ("App::PropertyDistance", "TolHigh",
     QT_TRANSLATE_NOOP("App::Property", "Upper limit of the tolerance band"),
     0.01),
    ("App::PropertyEnumeration", "Unit",
     QT_TRANSLATE_NOOP("App::Property", "Unit of the legend and labels"),
     ["mm", "um"]),
    ("App::PropertyBool", "Points",
     QT_TRANSLATE_NOOP("App::Property", "Draw the measured points as coloured markers"),
     True),
    ("App::PropertyBool", "Labels",
     QT_TRANSLATE_NOOP("App::Property", "Label the largest positive and negative value"),
     True),
    ("App::PropertyBool", "Legend",
     QT_TRANSLATE_NOOP("App::Property", "Draw the colour bar legend"),
     True),
    ("App::PropertyBool", "Stepped",
     QT_TRANSLATE_NOOP("App::Property", "Stepped colour bar: one flat colour per legend step"),
     False),
    ("App::PropertyBool", "Shared",
     QT_TRANSLATE_NOOP("App::Property", "AutoRange over every map of the same measurement "
                                        "(deviation, determined, random, correction), so the "
                                        "maps compare by colour"),
     False),
    ("App::PropertyFloat", "WarnBand",
     QT_TRANSLATE_NOOP("App::Property", "Tolerance band mode: warning limit as a fraction of the "
                                        "tolerance (0.8: the outer 20 % warn in yellow; 0: off)"),
     0.0),
    ("App::PropertyBool", "Histogram",
     QT_TRANSLATE_NOOP("App::Property", "Show the histogram panel of this map, coloured like its "
                                        "legend"),
     False),
    ("App::PropertyBool", "HideStock",
     QT_TRANSLATE_NOOP("App::Property", "While this map is shown, a CAM Job's stock around it "
                                        "is not drawn and takes no clicks (its Visibility is "
                                        "kept)"),
     True),
    ("App::PropertyIntegerList", "Flags",
     QT_TRANSLATE_NOOP("App::Property", "Measured nodes flagged on the map (click the map to add "
                                        "or remove one; empty this list to remove all)"),
     None),
    ("App::PropertyInteger", "MapVersion",
     QT_TRANSLATE_NOOP("App::Property", "Property set version of this view"),
     VERSION),
)


def add_map_properties(vobj, from_preferences=True):
    """Add the missing colour-map properties to ``vobj`` (new objects, old documents: their
    renamed properties' values move to the new names)."""
    old_names = [o for o in RENAMED if o in vobj.PropertiesList]
    added = []
    for typ, name, tip, default in MAP_PROPERTIES:
        if name in vobj.PropertiesList:
            continue
        added.append(name)
        vobj.addProperty(typ, name, _G, tip)
        if default is not None:
            setattr(vobj, name, default)
        if typ == "App::PropertyEnumeration":
            setattr(vobj, name, default[0])
    if "Unit" in added and "LegendUnit" not in old_names:
        # no unit stored in the document (made without the GUI, or before the unit was a
        # choice): the preference's (default um); a stored choice, mm or um, is kept
        vobj.Unit = prefs.display_unit()
    vobj.setEditorMode("MapVersion", 2)
    for old in old_names:
        setattr(vobj, RENAMED[old], getattr(vobj, old))
        vobj.removeProperty(old)
    if old_names or vobj.MapVersion < VERSION:
        vobj.MapVersion = VERSION
    if from_preferences:
        vobj.Scheme = prefs.scheme()
        vobj.TolBand = prefs.tolerance_band()
        vobj.TolLow, vobj.TolHigh = prefs.tolerance()
        vobj.Unit = prefs.display_unit()


def has_map_properties(vobj):
    """True once every colour-map property exists (they are added, and restored from a
    file, one at a time: ``onChanged`` fires in between)."""
    names = set(vobj.PropertiesList)
    return all(p[1] in names for p in MAP_PROPERTIES)


def style_of(vobj, quantity=None, shared=None):
    """The :class:`MapStyle` the view properties describe, checked
    (:func:`surfcomp.gui.map_style.style_of`; ``shared``: the common range when Shared is
    on)."""
    return map_style.style_of(vobj, quantity, shared, NOTES)


def arrange_legends(doc=None, changed=None):
    """Bring the legend panel up to date with the shown maps (once the current event is
    done: many maps change in one step)."""
    from . import legend

    legend.schedule()


class _MapViewProvider:
    """What both view providers share: the map properties, one Coin display mode (``MODE``)
    holding a :class:`MapScene`, and no saved state (the data lives in the object)."""

    MODE = ""
    ICON = ""

    def __init__(self, vobj):
        add_map_properties(vobj)
        vobj.Proxy = self

    def _reset(self):
        """Forget transient state (never saved)."""

    #: set when the object is deleted (until it is drawn again: undo)
    _deleted = False

    def forget(self):
        """The object or its document is deleted: no legend, no camera watch."""
        from . import flags

        self._deleted = True
        flags.watch(self, None)

    def attach(self, vobj):
        self.Object = vobj.Object
        self.vobj = vobj
        self._reset()
        self.scene = MapScene()
        vobj.addDisplayMode(self.scene.root, self.MODE)

    def getDisplayModes(self, vobj):
        return [self.MODE]

    def getDefaultDisplayMode(self):
        return self.MODE

    def setDisplayMode(self, mode):
        if mode == self.MODE:
            self.redraw()
        return mode

    def getIcon(self):
        return paths.icon(self.ICON)

    def onDocumentRestored(self, vobj):
        add_map_properties(vobj, from_preferences=False)

    def redraw(self):
        raise NotImplementedError

    def outside_names(self):
        """Names of the measured points outside the trimmed face (none drawn on it)."""
        return []

    def legend_entry(self):
        """``(key, name, legend data, outside point names)`` for the legend panel, or None
        when this map's legend is not shown."""
        vobj = getattr(self, "vobj", None)
        scene = getattr(self, "scene", None)
        if vobj is None or scene is None or getattr(self, "_deleted", False) \
                or not has_map_properties(vobj) \
                or not vobj.Visibility or vobj.DisplayMode != self.MODE \
                or scene.legend_data is None or scene.range is None:
            return None
        obj = vobj.Object
        return ((obj.Document.Name, obj.Name), obj.Label, scene.legend_data,
                self.outside_names())


    def dumps(self):
        return None

    def loads(self, state):
        return None

    __getstate__ = dumps

    def __setstate__(self, state):
        return None


class ViewProviderCompensation(_MapViewProvider):
    """View provider of ``SurfComp_Compensation``: Part display modes plus ``Map``."""

    MODE = "Map"
    ICON = "SurfComp_DeviationMap.svg"

    # transient state only (never saved)
    def _reset(self):
        self._data = {}

    def claimChildren(self):
        meas = getattr(self.Object, "Measurement", None)
        return [meas] if meas is not None else []

    def updateData(self, obj, prop):
        if prop not in RESULT_PROPERTIES:
            return
        self._data = {}
        if getattr(self, "vobj", None) is None or self.vobj.DisplayMode != "Map":
            return
        if getattr(obj.Document, "Restoring", False):
            self._schedule()        # properties arrive one by one: draw once they are all in
        elif prop == "Shape":       # written last by a recompute
            self.redraw()
        else:                       # a preview recompute writes the components, no Shape
            self._schedule()

    def _schedule(self):
        self._dirty = True
        if not getattr(self, "_pending", False):
            self._pending = True
            QtCore.QTimer.singleShot(0, self._deferred)

    def _deferred(self):
        self._pending = False
        if getattr(self, "_dirty", False) and getattr(self, "vobj", None) is not None \
                and self.vobj.DisplayMode == "Map":
            self.redraw()

    def finishRestoring(self):
        self._schedule()

    def onChanged(self, vobj, prop):
        if getattr(self, "_syncing", False) or not hasattr(self, "scene") \
                or not has_map_properties(vobj):
            return
        if prop in STYLE_PROPERTIES:
            self.restyle()
        elif prop == "Map" and vobj.DisplayMode == "Map":
            self.redraw()
        elif prop == "Flags":
            self.draw_flags()
        elif prop in ("Visibility", "DisplayMode", "HideStock"):
            arrange_legends()
            cover.update(getattr(vobj.Object, "Document", None))
            if prop == "Visibility" and not vobj.Visibility:
                from . import histogram

                histogram.close_map(vobj)

    def redraw(self):
        """Draw the current quantity (mesh and values are cached per Shape)."""
        vobj = getattr(self, "vobj", None)
        if vobj is None or not has_map_properties(vobj):
            return
        self._dirty = False
        self._deleted = False
        obj = vobj.Object
        q = vobj.Map
        if not obj.GridRows or not obj.GridCols or obj.Shape.isNull():
            self.scene.clear()      # not computed yet: nothing to draw
            return
        try:
            if q not in self._data:
                key = mesh_key(obj)     # the mesh outlives result changes (filter preview)
                if getattr(self, "_mesh", (None,))[0] != key:
                    self._mesh = (key, map_mesh(obj), {})
                self._data[q] = map_data(obj, q, mesh=self._mesh[1], located=self._mesh[2])
        except SurfcompError as exc:
            self.scene.clear()
            FreeCAD.Console.PrintWarning("%s: no map: %s\n" % (obj.Label, exc))
            return
        d = self._data[q]
        self.scene.set_data(d["points"], d["triangles"], d["values"], d["markers"],
                            d["marker_values"], title=TITLES[q], restyle=False)
        self.restyle()
        self.draw_flags()
        cover.update(obj.Document)
        from . import readout

        readout.install()

    def shared_range(self):
        """The common range of the maps of this measurement (Shared), or None."""
        vobj = self.vobj
        if not vobj.Shared or not vobj.AutoRange:
            return None
        obj = vobj.Object
        same = [o for o in obj.Document.Objects if features.is_compensation(o)
                and o.Measurement is obj.Measurement and o.GridRows]
        return reports.common_range(same)

    def restyle(self, arrange=True):
        """Recolour from the view properties (no new geometry, no recompute)."""
        vobj = self.vobj
        style = style_of(vobj, vobj.Map, self.shared_range())
        self.scene.set_style(style)
        map_style.report(self, style)
        arrange_legends()
        if vobj.AutoRange and self.scene.range is not None and not np.allclose(
                (vobj.RangeMin.Value, vobj.RangeMax.Value), self.scene.range,
                rtol=1e-12, atol=1e-15):
            # show the automatic range in the (then unused) manual fields; only a change
            # is written: a write marks the document modified (one just opened included)
            self._syncing = True
            try:
                vobj.RangeMin, vobj.RangeMax = self.scene.range
            finally:
                self._syncing = False
        from . import histogram

        if vobj.Histogram and self.scene.range is not None and vobj.Visibility:
            histogram.show_map(vobj, self.scene)
        else:
            histogram.close_map(vobj)

    def outside_names(self):
        d = self._data.get(self.vobj.Map)
        if d is None or not len(d["outside"]):
            return []
        if "_outside" not in self._data:
            try:
                ids = self.locator().ids
            except SurfcompError:
                ids = None
            self._data["_outside"] = [ids[k] if ids else "node %d" % k for k in d["outside"]]
        return self._data["_outside"]

    def locator(self):
        """The :class:`~surfcomp.app.reports.PointLocator` of the drawn result (cached)."""
        if "_locator" not in self._data:
            self._data["_locator"] = reports.PointLocator(self.vobj.Object)
        return self._data["_locator"]

    def draw_flags(self):
        """Flag labels at the nodes listed in the view's ``Flags``."""
        vobj = getattr(self, "vobj", None)
        if vobj is None or self._deleted or not has_map_properties(vobj) \
                or self.scene.range is None:
            return
        flags = []
        unit = vobj.Unit
        try:
            loc = self.locator() if len(vobj.Flags) else None
        except SurfcompError:
            loc = None
        for node in vobj.Flags if loc is not None else ():
            if 0 <= node < len(loc.nodes):
                info = loc.node(node)
                value = info[vobj.Map] if vobj.Map in info else info["deviation"]
                flags.append((info["local"], "%s  %s" % (info["id"], colormap.format_value(
                    value, unit))))
        from . import flags as flag_layout

        self.scene.set_flags(flag_layout.for_map(self, flags))

    def toggle_flag(self, node):
        """Add a flag at ``node`` or remove the one there (saved with the document)."""
        flags = list(self.vobj.Flags)
        if node in flags:
            flags.remove(node)
        else:
            flags.append(int(node))
        self.vobj.Flags = flags

    def setEdit(self, vobj, mode=0):
        if mode != 0:
            return None
        import FreeCADGui

        from .panels import FilterPanel

        FreeCADGui.Control.showDialog(FilterPanel(vobj.Object))
        return True

    def unsetEdit(self, vobj, mode=0):
        import FreeCADGui

        FreeCADGui.Control.closeDialog()
        return True

    def doubleClicked(self, vobj):
        import FreeCADGui

        FreeCADGui.ActiveDocument.setEdit(vobj.Object.Name, 0)
        return True



class ViewProviderMeasurement(_MapViewProvider):
    """View provider of ``SurfComp_Measurement``: the points as markers, coloured by the
    file's deviation when it has one."""

    MODE = "Points"
    ICON = "SurfComp_ImportMeasurements.svg"

    def updateData(self, obj, prop):
        if prop in ("NominalX", "MeasuredX", "Deviation") and hasattr(self, "scene"):
            self.redraw()

    def onChanged(self, vobj, prop):
        if not hasattr(self, "scene") or not has_map_properties(vobj):
            return
        if prop in STYLE_PROPERTIES:
            self.redraw()
        elif prop in ("Visibility", "DisplayMode") and vobj.Object.Document is not None:
            arrange_legends(vobj.Object.Document)

    def redraw(self):
        vobj = getattr(self, "vobj", None)
        if vobj is None or not has_map_properties(vobj):
            return
        self._deleted = False
        obj = vobj.Object
        ms = features.measurement_set(obj)
        pts = ms.nominal if ms.nominal is not None else ms.measured
        if pts is None or len(pts) == 0:
            self.scene.clear()
            return
        values = ms.deviation if ms.deviation is not None else np.zeros(len(pts))
        self.scene.set_data(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32), values,
                            pts, values, title="Deviation (file)")
        self.restyle()

    def restyle(self, arrange=True):
        vobj = self.vobj
        style = style_of(vobj, "deviation")
        if not has_deviation(vobj.Object):
            style.show_legend = style.show_labels = False
        self.scene.set_style(style)
        map_style.report(self, style)
        arrange_legends()



def has_deviation(obj):
    """True when a measurement object holds deviations (its map has a legend)."""
    return len(getattr(obj, "Deviation", [])) > 0


def attach(obj):
    """Give a surfcomp object its view provider (registered as a creation hook of
    :mod:`surfcomp.app.features`, and called by the commands' macros; idempotent)."""
    if obj.ViewObject is None or isinstance(getattr(obj.ViewObject, "Proxy", None),
                                            (ViewProviderCompensation, ViewProviderMeasurement)):
        return
    if features.is_compensation(obj):
        ViewProviderCompensation(obj.ViewObject)
    elif features.is_measurement(obj):
        ViewProviderMeasurement(obj.ViewObject)



def attach_all(doc):
    """Give every surfcomp object of ``doc`` without one its view provider and show its map
    (documents made headless, e.g. by ``compensate --save``); returns those objects."""
    return [obj for obj in doc.Objects if attach_restored(obj)]


def attach_restored(obj):
    """:func:`attach_all` for one object (also run while its document is being opened,
    :data:`surfcomp.app.features.RESTORED_HOOKS`); True when it got its view provider."""
    if not (features.is_compensation(obj) or features.is_measurement(obj)):
        return False
    vobj = obj.ViewObject
    # a view object whose proxy was never set reports 0 (FreeCAD 0.20), not None
    if vobj is None or isinstance(vobj.Proxy, (ViewProviderCompensation,
                                               ViewProviderMeasurement)):
        return False
    attach(obj)
    proxy = vobj.Proxy
    if not hasattr(proxy, "scene"):  # an existing view object: FreeCAD does not attach
        proxy.attach(vobj)
    mode = proxy.getDisplayModes(vobj)[0]
    modes = list(vobj.getEnumerationsOfProperty("DisplayMode") or [])
    if mode not in modes:  # the enumeration was made before the proxy existed
        vobj.DisplayMode = modes + [mode]
    vobj.DisplayMode = mode
    return True


class _RestoreObserver:
    """App document observer: view providers for surfcomp objects of opened documents
    (0.20 has no restore slot for Python observers: an opened document is activated)."""

    def slotActivateDocument(self, doc):
        attach_all(doc)
        arrange_legends()       # the legend panel shows the active document's maps
        cover.update(doc)       # maps drawn while it opened met stocks not yet restored

    def slotRecomputedDocument(self, doc):
        attach_all(doc)

    def slotDeletedObject(self, obj):
        proxy = getattr(getattr(obj, "ViewObject", None), "Proxy", None)
        if isinstance(proxy, _MapViewProvider):
            proxy.forget()
            arrange_legends()
            cover.update(obj.Document)

    def slotDeletedDocument(self, doc):
        from . import flags

        flags.forget(doc.Name)      # (the view objects are gone already)
        cover.forget(doc.Name)
        arrange_legends()


_OBSERVER = []


def install_observer():
    """Watch opened documents (once per session) and treat those already open."""
    if not _OBSERVER:
        _OBSERVER.append(_RestoreObserver())
        FreeCAD.addDocumentObserver(_OBSERVER[0])
    for doc in FreeCAD.listDocuments().values():
        attach_all(doc)


if attach not in features.NEW_OBJECT_HOOKS:
    features.NEW_OBJECT_HOOKS.append(attach)
if attach_restored not in features.RESTORED_HOOKS:
    features.RESTORED_HOOKS.append(attach_restored)
