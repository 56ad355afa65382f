# SPDX-License-Identifier: LGPL-2.1-or-later
"""Replace the nominal by the compensation in the document, and restore it.

:func:`replace` rebinds every object that uses the nominal (a Path Job's model clone,
operations' ``Base`` links, other features' links, sub-element links like
``(obj, 'Face6')``) to the compensation feature, hides the nominal and keeps it
unchanged. What it changed is recorded on the compensation (``ReplacedLinks``, saved with
the document), so :func:`restore` puts back exactly the previous links, also after the
document was saved and reopened.

For an iteration (a compensation with a ``Base``) the users of the nominal *and* of the
previous compensations in the chain move to the new one.

Each call is one transaction (one undo step in the GUI); when anything fails the
document is exactly as before: every link, visibility and record is put back and the
objects that were not touched before are not touched after.
"""

import json

from ..errors import GeometryError, InputError
from . import cam, features
from .plan_feature import PLAN_TYPE
from .undo import UndoStep

#: properties never rebound: group membership and the compensation's own inputs
SKIP_PROPERTIES = ("Group", "ExpressionEngine", "InList", "OutList")


def _kind(typeid):
    """Link property kinds by their type id: 'link', 'list', 'sub', 'sublist' or None."""
    if "Link" not in typeid or not typeid.startswith("App::Property"):
        return None
    t = typeid[len("App::Property"):]
    if t.startswith("X"):
        t = t[1:]
    for suffix in ("Child", "Global", "Hidden"):
        if t.endswith(suffix):
            t = t[: -len(suffix)]
    return {"Link": "link", "LinkList": "list", "LinkSub": "sub",
            "LinkSubList": "sublist"}.get(t)


def _encode(kind, value):
    """A JSON-able form of a link property value (object names)."""
    if kind == "link":
        return value.Name if value is not None else None
    if kind == "list":
        return [o.Name for o in value]
    if kind == "sub":
        return None if not value else [value[0].Name, list(value[1])]
    return [[o.Name, list(subs) if isinstance(subs, (list, tuple)) else [subs]]
            for o, subs in value]


def _decode(doc, kind, data):
    def obj(name):
        o = doc.getObject(name)
        if o is None:
            raise InputError("cannot restore a link to %s: the object is gone" % name)
        return o

    if kind == "link":
        return obj(data) if data else None
    if kind == "list":
        return [obj(n) for n in data]
    if kind == "sub":
        return None if not data else (obj(data[0]), list(data[1]))
    return [(obj(n), tuple(subs)) for n, subs in data]


def _map_subs(subs, mapping, where, label):
    if mapping is None:
        return list(subs)
    out = []
    for s in subs:
        if s == "" or s in mapping:
            out.append(mapping.get(s, s))
        else:
            raise GeometryError("%s links %s of the nominal, which the face output of %s "
                                "does not have: set %s's Output to solid"
                                % (where, s, label, label))
    return out


def _replaces(obj):
    """A compensation, or a region compensation (:mod:`surfcomp.app.region_doc`)."""
    from .region_doc import is_region

    return features.is_compensation(obj) or is_region(obj)


def _chain(comp):
    """``comp`` and its earlier rounds, newest first."""
    from .region_doc import chain, is_region

    return chain(comp) if is_region(comp) else features.chain(comp)


def _targets(comp):
    """Objects whose users move to ``comp``: its nominal and the earlier rounds."""
    return [comp.Nominal] + _chain(comp)[1:]


def _sub_mapping(comp):
    """Sub-element names of a target -> names on the compensation's shape, or None when
    every name stays (solid output, or a nominal that is the face itself: the rebuilt face
    keeps the order of its edges and vertices)."""
    if comp.Output == "solid" or len(comp.Nominal.Shape.Faces) == 1:
        return None
    return {comp.FaceName: "Face1"}


def _rebound(value, kind, names, comp, mapping, where):
    """``value`` of a link property with the targets (``names``) replaced by ``comp``, or
    None when it links none of them."""
    def subs_of(old):
        return _map_subs(old, mapping, where, comp.Label)

    if kind == "link":
        return comp if value is not None and value.Name in names else None
    if kind == "list":
        if not any(x.Name in names for x in value):
            return None
        return [comp if x.Name in names else x for x in value]
    if kind == "sub":
        if not value or value[0].Name not in names:
            return None
        return (comp, subs_of(list(value[1])))
    pairs = [(x, list(subs) if isinstance(subs, (list, tuple)) else [subs]) for x, subs in value]
    if not any(x.Name in names for x, _subs in pairs):
        return None
    return [(comp, tuple(subs_of(subs))) if x.Name in names else (x, tuple(subs))
            for x, subs in pairs]


def plan(doc, comp):
    """What :func:`replace` would change: a list of ``(object, property, kind, old, new)``.

    Raises
    ------
    GeometryError
        A sub-element link to a face that the compensation's output does not have.
    """
    names = {t.Name for t in _targets(comp)}
    mapping = _sub_mapping(comp)
    clones = set()
    changes = []
    for o in doc.Objects:
        # measurements and measurement plans stay with the nominal: deviations are
        # against it, never against the corrected face
        if o is comp or _replaces(o) or features.is_measurement(o) or \
                features.is_type(o, PLAN_TYPE):
            continue
        for prop in o.PropertiesList:
            kind = None if prop in SKIP_PROPERTIES else _kind(o.getTypeIdOfProperty(prop))
            if kind is None:
                continue
            old = getattr(o, prop)
            new = _rebound(old, kind, names, comp, mapping, "%s.%s" % (o.Label, prop))
            if new is None:
                continue
            changes.append((o, prop, kind, old, new))
            if kind == "list" and o.isDerivedFrom("Part::Feature") and len(old) == 1:
                clones.add(o.Name)      # a clone of the nominal (Draft, Path model)
    if mapping is not None and clones:
        # a clone of the nominal (Path's model, Draft) gets the face output's single face,
        # so links to the clone's FaceN would point elsewhere
        raise GeometryError("%s is cloned by %s: with the face output a clone would keep only "
                            "the compensated face of the %d faces of %s, and links to its "
                            "faces would move: set %s's Output to solid"
                            % (comp.Nominal.Label, ", ".join(sorted(clones)),
                               len(comp.Nominal.Shape.Faces), comp.Nominal.Label, comp.Label))
    return changes


def _plain(subs):
    """Sub-element names without FreeCAD 1.x's ``'?'`` mark of an unresolved name."""
    return [x.lstrip("?") for x in (subs if isinstance(subs, (list, tuple)) else [subs])]


def _element_links(obj):
    """``(user, property, value)`` of every sub-element link to ``obj``, names plain."""
    out = []
    for user in obj.InList:
        for prop in user.PropertiesList:
            kind = None if prop in SKIP_PROPERTIES else _kind(user.getTypeIdOfProperty(prop))
            if kind not in ("sub", "sublist"):
                continue
            value = getattr(user, prop)
            if kind == "sub" and value and value[0] is obj:
                out.append((user, prop, (obj, _plain(value[1]))))
            elif kind == "sublist" and any(x is obj for x, _subs in value):
                out.append((user, prop, [(x, tuple(_plain(subs))) for x, subs in value]))
    return out


def _relink_elements(undo, changes):
    """Keep ``(clone, 'FaceN')`` links valid when a clone's shape is swapped.

    FreeCAD 1.x traces sub-element links through the topological naming's element map.
    A clone (Path's model) whose source changes from the nominal to the compensation gets
    an unrelated shape, so at its next recompute its users' links become ``'?Face1'``
    (unresolved) and the operations fail. The clones are recomputed here and their users'
    links set again by name: the faces keep their names (same faces, same order). On 0.20
    this sets the same values again.
    """
    reshaped = [o for o, _prop, kind, _old, _new in changes
                if kind in ("link", "list") and o.isDerivedFrom("Part::Feature")]
    for obj in reshaped:
        links = _element_links(obj)
        obj.recompute()
        for user, prop, value in links:
            undo.set(user, prop, value)


def _snapshot(doc, objs):
    return {o.Name: ("Touched" in o.State) for o in objs}


def _assign(o, prop, value):
    """Set a property; a label exactly as given when it is free (:func:`cam.set_label`)."""
    if prop == "Label":
        cam.set_label(o, value)
    else:
        setattr(o, prop, value)


class _Undo:
    """Puts back what a failed replace/restore changed (with or without undo support)."""

    def __init__(self, doc):
        self.doc = doc
        self.steps = []
        self.touched = _snapshot(doc, doc.Objects)

    def set(self, o, prop, value):
        self.steps.append((o, prop, getattr(o, prop)))
        _assign(o, prop, value)

    def set_record(self, o, prop, value):
        """Set a property that records what was done (``ReplacedLinks``), not an input of
        ``o``'s computation: ``o`` stays untouched, so it is not recomputed for it."""
        was_touched = "Touched" in o.State
        self.set(o, prop, value)
        if not was_touched:
            o.purgeTouched()

    def rollback(self):
        for o, prop, value in reversed(self.steps):
            _assign(o, prop, value)
        for o in self.doc.Objects:
            if o.Name in self.touched and not self.touched[o.Name] and "Touched" in o.State:
                o.purgeTouched()


def _run(doc, name, work):
    undo = _Undo(doc)
    with UndoStep(doc, name, rollback=undo.rollback):
        return work(undo)


def _check_computed(comp):
    if comp.Shape.isNull() or "Invalid" in comp.State or "Error" in comp.State:
        raise InputError("%s is not computed (state %s): recompute it and fix its errors "
                         "before replacing the nominal" % (comp.Label, ", ".join(comp.State)))


def _check_restored(doc, comp):
    """Refuse when users of the nominal, or the CAM Jobs they belong to (with their
    operations, stock and tools), lost their Python objects at open time: their tool paths
    could not follow the new face, and a save would make the loss permanent."""
    from . import cam_job, toolpaths

    users = {}
    for target in _targets(comp):
        users.update((o.Name, o) for o in target.InListRecursive)
    for job in cam_job.jobs_of(doc):
        if job.Name in users:
            users.update((o.Name, o) for o in job.OutListRecursive)
    lost = toolpaths.lost_labels(sorted(users.values(), key=lambda o: o.Name))
    if lost:
        raise InputError("%d object(s) that use %s lost their Python objects when the document "
                         "was opened (a module they need could not be imported): %s. Their "
                         "tool paths cannot follow the corrected face, and saving would lose "
                         "them, so nothing was replaced. Close the document without saving, "
                         "make the modules importable (OpenCamLib for the 3D Surface "
                         "operation: tools/install.sh; FreeCAD 0.20's CAM modules resolve on "
                         "1.x when surfcomp is installed before FreeCAD starts) and open it "
                         "again" % (len(lost), comp.Nominal.Label, "; ".join(lost)))


def _check_surface_dressups(doc, comp, changes):
    """Refuse to move a Job that holds a "Surface correction" dressup
    (:mod:`surfcomp.app.dressup_surface`) onto the compensation: that dressup moves the
    operation's program by a correction already, and once the operation cuts the corrected
    face it would move it a second time (the dressup's command refuses the other order)."""
    from .cam_job import jobs_of
    from .dressup_surface import SURFACE_DRESSUP_TYPE

    changed = {o.Name for o, _prop, _kind, _old, _new in changes}
    for job in jobs_of(doc):
        inside = job.OutListRecursive
        if not changed & ({o.Name for o in inside} | {job.Name}):
            continue
        for o in inside:
            if features.is_type(o, SURFACE_DRESSUP_TYPE):
                follows = getattr(o.Compensation, "Label", "no compensation")
                raise InputError("%s holds the surface correction dressup %s, which moves its "
                                 "program by the correction of %s already: with %s in the "
                                 "nominal's place its operation would cut the corrected face "
                                 "and the dressup would move that a second time; nothing was "
                                 "replaced. Expected one correction: delete the dressup first, "
                                 "or point its Compensation at %s instead of replacing"
                                 % (job.Label, o.Label, follows, comp.Label, comp.Label))


def replace(doc, comp):
    """Rebind the users of ``comp``'s nominal to ``comp``; hide the nominal.

    Parameters
    ----------
    doc : FreeCAD document
    comp : ``SurfComp_Compensation`` (computed; recompute the document first)

    Returns
    -------
    list of (object name, property name)
        The links that now point to ``comp``. Recompute the document afterwards so the
        users (Path operations) regenerate.

    Raises
    ------
    InputError
        ``comp`` is not a computed compensation or is already replacing its nominal, or
        users of the nominal (or their CAM Jobs) lost their Python objects at open time, or
        a Job it would move holds a surface correction dressup.
    GeometryError
        A user links a face the compensation's output does not have.
    """
    if not _replaces(comp):
        raise InputError("%s is not a surfcomp compensation" % comp.Label)
    if comp.ReplacedLinks:
        raise InputError("%s already replaces its nominal (restore it first)" % comp.Label)
    _check_computed(comp)
    _check_restored(doc, comp)
    nominal = comp.Nominal

    def work(undo):
        changes = plan(doc, comp)
        if not changes:
            raise InputError("nothing in the document uses %s (no Path job, clone or other "
                             "feature links it): there is nothing to replace; export the "
                             "corrected face with Build corrected face instead"
                             % nominal.Label)
        _check_surface_dressups(doc, comp, changes)
        record = {"links": [], "visibility": {}, "labels": {}}
        for o, prop, kind, old, new in changes:
            record["links"].append({"object": o.Name, "property": prop, "kind": kind,
                                    "old": _encode(kind, old)})
            undo.set(o, prop, new)
        _relink_elements(undo, changes)
        for o in _clones(changes):
            # a clone named after the nominal (Path's "Model-nominal") is named after comp
            if nominal.Label in o.Label:
                record["labels"][o.Name] = o.Label
                undo.set(o, "Label", o.Label.replace(nominal.Label, comp.Label))
        for o, vis in ((nominal, False), (comp, True)):
            if "Visibility" in o.PropertiesList:
                record["visibility"][o.Name] = bool(o.Visibility)
                undo.set(o, "Visibility", vis)
        for earlier in _chain(comp)[1:]:
            if "Visibility" in earlier.PropertiesList and earlier.Visibility:
                record["visibility"][earlier.Name] = True
                undo.set(earlier, "Visibility", False)
        undo.set_record(comp, "ReplacedLinks", json.dumps(record, sort_keys=True))
        return [(o.Name, prop) for o, prop, _k, _o, _n in changes]

    return _run(doc, "Replace %s by %s" % (nominal.Label, comp.Label), work)


def restore(doc, comp):
    """Undo :func:`replace`: put back the recorded links and visibilities.

    Returns
    -------
    list of (object name, property name)
        The links that were put back.
    """
    if not _replaces(comp):
        raise InputError("%s is not a surfcomp compensation" % comp.Label)
    if not comp.ReplacedLinks:
        raise InputError("%s does not replace its nominal (nothing to restore)" % comp.Label)
    later = [o.Label for o in doc.Objects if o is not comp and _replaces(o)
             and is_replacing(o) and any(x is comp for x in _chain(o)[1:])]
    if later:
        # its users moved on to the later round: putting back its record would take them
        # from that round to the nominal and leave the later round's record pointing at
        # links that no longer use it
        raise InputError("%s: %s, a later round of its iteration, replaces it now; restore "
                         "%s first" % (comp.Label, ", ".join(later), later[0]))
    try:
        record = json.loads(comp.ReplacedLinks)
    except ValueError as exc:
        raise InputError("%s: the replace record is damaged (%s)" % (comp.Label, exc)) from exc

    def work(undo):
        done = []
        changes = []
        for item in record.get("links", []):
            o = doc.getObject(item["object"])
            if o is None:
                continue    # the user deleted it meanwhile: nothing to put back
            old = _decode(doc, item["kind"], item["old"])
            changes.append((o, item["property"], item["kind"], None, old))
            undo.set(o, item["property"], old)
            done.append((o.Name, item["property"]))
        _relink_elements(undo, changes)
        for name, vis in record.get("visibility", {}).items():
            o = doc.getObject(name)
            if o is not None and "Visibility" in o.PropertiesList:
                undo.set(o, "Visibility", bool(vis))
        for name, label in record.get("labels", {}).items():
            o = doc.getObject(name)
            if o is not None:
                undo.set(o, "Label", label)
        undo.set_record(comp, "ReplacedLinks", "")
        return done

    return _run(doc, "Restore %s" % getattr(comp.Nominal, "Label", "nominal"), work)


def _clones(changes):
    """The Part features among the changed objects that copy one source (clones, Path's
    model clone)."""
    seen = []
    for o, _prop, kind, _old, new in changes:
        if kind in ("link", "list") and o.isDerivedFrom("Part::Feature") and o not in seen \
                and (kind == "link" or len(new) == 1):
            seen.append(o)
    return seen


def summary(doc, comp):
    """What :func:`replace` changed, from its record on ``comp``: ``objects`` (labels of
    the objects whose links were rebound), ``links`` (number of link properties),
    ``jobs`` and ``job_names`` (labels and names of the Path jobs that use a rebound
    object: what happened to their tool paths is :mod:`surfcomp.app.toolpaths`), ``renamed``
    (``(old label, new label)``), ``deleted`` (names of rebound objects deleted since: their
    links count nowhere, and :func:`restore` skips them)."""
    try:
        record = json.loads(comp.ReplacedLinks or "{}")
    except ValueError:
        record = {}
    names = []
    for item in record.get("links", []):
        if item["object"] not in names:
            names.append(item["object"])
    objs = [doc.getObject(n) for n in names if doc.getObject(n) is not None]
    from .cam_job import jobs_of

    jobs = []
    for job in jobs_of(doc):
        used = {o.Name for o in job.OutListRecursive} | {job.Name}
        if used & set(names):
            jobs.append(job)
    renamed = [(old, doc.getObject(n).Label) for n, old in record.get("labels", {}).items()
               if doc.getObject(n) is not None]
    links = [item for item in record.get("links", []) if doc.getObject(item["object"])]
    return {"objects": [o.Label for o in objs], "links": len(links),
            "jobs": [j.Label for j in jobs], "job_names": [j.Name for j in jobs],
            "renamed": renamed, "deleted": [n for n in names if doc.getObject(n) is None]}


def is_replacing(comp):
    """True when ``comp`` currently replaces its nominal."""
    return bool(getattr(comp, "ReplacedLinks", ""))


__all__ = ["replace", "restore", "plan", "is_replacing", "summary"]
