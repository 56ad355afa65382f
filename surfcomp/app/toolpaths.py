# SPDX-License-Identifier: LGPL-2.1-or-later
"""What a recompute did to the tool paths of the CAM Jobs, so no summary claims more.

Replace, Restore and the command line's document route report per operation what
happened, from the operation's commands before and after the recompute
(:func:`snapshot`, then :func:`compare`):

- ``regenerated``: the operation recomputed without error and its commands changed;
- ``unchanged``: no error, the same commands as before;
- ``failed``: the operation is in error (FreeCAD's status message is kept), or the CAM
  workbench logged an error while it recomputed (those messages are kept): many operations
  log their failure and return, keeping an old or a truncated path in an object FreeCAD
  marks recomputed (:func:`surfcomp.app.progress.failed`);
- ``lost``: its Python object did not restore when the document was opened (a module it
  needs could not be imported), so it cannot recompute at all and keeps its old commands;
- ``inactive``: switched off (``Active`` false), Path does not recompute it;
- ``stale``: a dressup over an operation that failed or was lost: whatever it computed, it
  still follows the old tool path.

A command counts as changed when its name changes or one of its words (X, Y, Z, F, ...)
by more than :data:`TOLERANCE`: a document saved and reopened keeps fewer digits than a
recompute gives, which is no change of the tool path.

:func:`lost_proxies` finds the objects that lost their Python object; Replace refuses to
touch a document where the users of the nominal or their Jobs did (saving it would make the
loss permanent, and their tool paths could not follow the new face anyway).
"""

from dataclasses import dataclass, field

from . import cam_job
from . import progress as recompute_order

#: statuses of :class:`OperationReport`
STATUSES = ("regenerated", "unchanged", "inactive", "failed", "lost", "stale")

#: smallest change of a command's word that counts (mm, mm/min, ...): below the 4 decimals
#: a post-processor writes
TOLERANCE = 1e-4


@dataclass
class OperationReport:
    """What happened to one operation (``name``/``label`` of the document object)."""

    name: str
    label: str
    status: str
    commands: int = 0          # commands after the recompute
    before: int = 0            # commands before
    changed: int = 0           # commands that differ from the one at the same place before
    detail: str = ""           # FreeCAD's status message (failed), the base's label (stale)


@dataclass
class JobReport:
    """What happened to the operations of one Job; ``lost``: labels of the Job and its
    stock, tool controllers and setup sheet that lost their Python object."""

    name: str
    label: str
    operations: list = field(default_factory=list)
    lost: list = field(default_factory=list)

    def regenerated(self):
        return [op for op in self.operations if op.status == "regenerated"]


def has_lost_proxy(obj):
    """Whether ``obj`` is a Python feature whose Python object (proxy) is missing."""
    return ("Python" in obj.TypeId and "Proxy" in obj.PropertiesList
            and getattr(obj, "Proxy", None) is None)


def lost_proxies(objs):
    """Descriptions of the objects of ``objs`` whose Python object did not restore."""
    return ["%s (%s, label %r): its Python proxy was not restored (a module it needs could "
            "not be imported)" % (o.Name, o.TypeId, o.Label) for o in objs if has_lost_proxy(o)]


def lost_labels(objs):
    """``Name (TypeId, label 'Label')`` of the objects of ``objs`` that lost their Python
    object (short, for a list in one message)."""
    return ["%s (%s, label %r)" % (o.Name, o.TypeId, o.Label) for o in objs
            if has_lost_proxy(o)]


def _is_path_feature(obj):
    return obj is not None and hasattr(obj, "PropertiesList") and "Path" in obj.PropertiesList


def operations(job):
    """The operations of ``job``: each entry of its Operations group, then the operations
    under it (a dressup's ``Base`` chain)."""
    out = []
    for op in cam_job.operations_of(job):
        while _is_path_feature(op) and op not in out:
            out.append(op)
            base = getattr(op, "Base", None)
            op = base if _is_path_feature(base) else None
    return out


def _setup_objects(job):
    """The Job and what it holds besides operations: stock, tool controllers, setup sheet."""
    objs = [job]
    for prop in ("Stock", "SetupSheet"):
        if getattr(job, prop, None) is not None:
            objs.append(getattr(job, prop))
    tools = getattr(job, "Tools", None)
    for tc in getattr(tools, "Group", []) or []:
        objs.append(tc)
        objs.extend(o for o in getattr(tc, "OutList", []) if "Python" in o.TypeId)
    unique = []
    for o in objs:
        if all(o is not u for u in unique):
            unique.append(o)
    return unique


def _commands(op):
    return tuple((c.Name, tuple(sorted(c.Parameters.items()))) for c in op.Path.Commands)


def _same(a, b):
    (name_a, words_a), (name_b, words_b) = a, b
    return name_a == name_b and len(words_a) == len(words_b) and all(
        ka == kb and abs(va - vb) <= TOLERANCE for (ka, va), (kb, vb) in zip(words_a, words_b))


def snapshot(doc):
    """``{job name: {operation name: commands}}`` of every Job of ``doc``, before a change
    (the CAM errors logged at earlier recomputes are forgotten: :func:`compare` reports
    those of the recompute after the change)."""
    recompute_order.forget_cam_errors(doc)
    return {job.Name: {op.Name: _commands(op) for op in operations(job)}
            for job in cam_job.jobs_of(doc)}


def _changed(old, new):
    """Commands of ``new`` that differ from the one at the same place in ``old`` (those
    beyond the end of ``old`` count as changed)."""
    return sum(not _same(a, b) for a, b in zip(old, new)) + max(0, len(new) - len(old))


def _operation_report(op, old):
    new = _commands(op)
    rep = OperationReport(op.Name, op.Label, "unchanged", commands=len(new),
                          before=len(old) if old is not None else 0)
    if has_lost_proxy(op):
        rep.status = "lost"
    elif recompute_order.failed(op):
        rep.status = "failed"
        rep.detail = recompute_order.state_text(op)
    elif getattr(op, "Active", True) is False:
        rep.status = "inactive"
    elif old is None or len(new) != len(old) or _changed(old, new):
        rep.status = "regenerated"
        rep.changed = len(new) if old is None else _changed(old, new)
    return rep


def _mark_stale(ops, reports):
    """A dressup whose base operation failed or was lost follows the old tool path."""
    by_name = {r.name: r for r in reports}
    for op, rep in zip(ops, reports):
        base = getattr(op, "Base", None)
        while _is_path_feature(base) and rep.status in ("regenerated", "unchanged"):
            below = by_name.get(base.Name)
            if below is not None and below.status in ("failed", "lost"):
                rep.status, rep.detail = "stale", below.label
            base = getattr(base, "Base", None)


def compare(doc, before, jobs=None):
    """What happened to each Job's operations since :func:`snapshot` returned ``before``.

    Parameters
    ----------
    doc : FreeCAD document, recomputed since the snapshot
    before : dict from :func:`snapshot`
    jobs : iterable of str, optional
        Names of the Jobs to report (default: all).

    Returns
    -------
    list of JobReport
    """
    wanted = None if jobs is None else set(jobs)
    out = []
    for job in cam_job.jobs_of(doc):
        if wanted is not None and job.Name not in wanted:
            continue
        old = before.get(job.Name, {})
        rep = JobReport(job.Name, job.Label,
                        lost=[o.Label for o in _setup_objects(job) if has_lost_proxy(o)])
        ops = operations(job)
        rep.operations = [_operation_report(op, old.get(op.Name)) for op in ops]
        _mark_stale(ops, rep.operations)
        out.append(rep)
    return out


def _phrase(op, tr):
    if op.status == "regenerated" and op.commands == op.before:
        return tr("%s regenerated (%d of %d commands changed)") % (op.label, op.changed,
                                                                   op.commands)
    if op.status == "regenerated":
        return tr("%s regenerated (%d commands, %d before)") % (op.label, op.commands,
                                                                op.before)
    if op.status == "unchanged":
        return tr("%s: tool path unchanged") % op.label
    if op.status == "inactive":
        return tr("%s inactive, not regenerated") % op.label
    if op.status == "failed":
        return tr("%s NOT regenerated, it failed: %s") % (op.label, op.detail)
    if op.status == "stale":
        return tr("%s NOT regenerated: its base operation %s was not") % (op.label, op.detail)
    return tr("%s NOT regenerated: its Python object did not restore when the document "
              "was opened (a module it needs could not be imported)") % op.label


def describe(reports, tr=None):
    """One line per Job of ``reports`` (:func:`compare`) saying what happened to each of its
    operations; ``tr`` translates a format string (the GUI's ``translate``)."""
    tr = tr or (lambda text: text)
    lines = []
    for job in reports:
        parts = [_phrase(op, tr) for op in job.operations] or [tr("no operations")]
        if job.lost:
            parts.insert(0, tr("NOT regenerated: %s did not restore when the document was "
                               "opened") % ", ".join(job.lost))
        lines.append(tr("Path job %s: %s") % (job.label, "; ".join(parts)))
    return lines


def as_dicts(reports):
    """JSON-able form of ``reports`` (:func:`compare`)."""
    return [{"job": j.name, "label": j.label, "lost": list(j.lost),
             "operations": [vars(op).copy() for op in j.operations]} for j in reports]


__all__ = ["snapshot", "compare", "describe", "as_dicts", "lost_proxies", "lost_labels",
           "has_lost_proxy",
           "operations", "OperationReport", "JobReport", "STATUSES"]
