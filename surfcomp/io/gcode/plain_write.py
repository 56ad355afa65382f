# SPDX-License-Identifier: LGPL-2.1-or-later
"""Runs of plain G0/G1 lines (:mod:`.plain`) written as arrays (no FreeCAD).

What :class:`surfcomp.io.gcode.emitter._TextWriter` decides line by line for a plain move
in absolute mm, decided for a whole run at once: which axis numbers change (compared as
integers in units of the last decimal written, which is what comparing the formatted
numbers does), what the machine holds after each line, the words added for axes the line
does not name; the changed lines are then assembled from their pieces. Moves written as
more than one piece, and a first line whose modal motion the output has to restore, go
through the line-by-line writer (their ``LineInfo`` built by
:func:`surfcomp.io.gcode.plain.line_info`).
"""

import numpy as np

from .emitter import _fmt
from .plain import line_info, plain_groups
from .plain_bytes import stretch_text

#: numbers of at most this many units of their last decimal get their digits from
#: :func:`.plain_bytes.number_bytes` (exact in binary64 below 2**52)
_EXACT = 2 ** 52


def _round_units(x, d):
    """``round(x * 10**d)`` as ``'%.*f' % (d, x)`` rounds (ties as the exact binary value
    decides), as int64; ``x`` (n,) and ``d`` (n,) int."""
    scale = 10.0 ** d
    y = x * scale
    r = np.rint(y)
    frac = np.abs(y - np.floor(y) - 0.5)
    near = frac < 1e-9 + np.abs(y) * 1e-15
    out = r.astype(np.int64)
    for k in np.flatnonzero(near):
        out[k] = int(("%.*f" % (int(d[k]), x[k])).replace(".", ""))
    return out


def write_block(w, lines, base, runs):
    """The output text of a block of ``(content, ending)`` lines written by the
    :class:`~surfcomp.io.gcode.emitter._TextWriter` ``w`` (its ``block`` set), runs
    (:class:`surfcomp.io.gcode.plain.PlainRun`) as arrays.

    The writer's decisions are taken stretch by stretch in order (the line-by-line writer
    in between changes what the machine holds); the text of every stretch written as
    arrays is built once for the whole block (:func:`_block_text`), which costs a fixed
    number of array operations instead of that number per stretch."""
    out = []
    pending = []            # (index in out, what _text takes) of the stretches
    pos = 0
    w.few = 10 * (len(lines) - sum(r.stop - r.start for r in runs)) < len(lines)
    for run in runs:
        out.extend([w.line(base + k, c, e) for k, (c, e) in enumerate(lines[pos:run.start],
                                                                        pos)])
        _write_run(w, run, lines, base, out, pending)
        pos = run.stop
    out.extend([w.line(base + k, c, e) for k, (c, e) in enumerate(lines[pos:], pos)])
    for k, text in zip([k for k, _a in pending], _block_text([a for _k, a in pending])):
        out[k] = text
    return "".join(out)


def _one(w, run, k, lines, base, out):
    """Line ``k`` of the run through the line-by-line writer."""
    i = run.start + k
    c, e = lines[i]
    w.prog.lines[i] = line_info(run, k, run.first_move + k, c)
    out.append(w.line(base + i, c, e))


def _write_run(w, run, lines, base, out, pending):
    n = run.stop - run.start
    held = w.state.held
    if w.factor_prev != 1.0 or any(h is None for h in held):
        for k in range(n):
            _one(w, run, k, lines, base, out)
        return
    plan = w.plan
    moves = run.first_move + np.arange(n)
    special = plan.split[moves] | plan.keep[moves] | (plan.offsets[moves + 1]
                                                      - plan.offsets[moves] != 1)
    k = 0
    if not run.g_word[0] and w.out_motion != int(run.motion[0]):
        special[0] = True
    for s in np.flatnonzero(special).tolist() + [n]:
        if s > k:
            _write_plain(w, run, k, s, lines, base, out, pending)
        if s < n:
            _one(w, run, s, lines, base, out)
        k = s + 1


def _write_plain(w, run, k0, k1, lines, base, out, pending):
    """Lines ``k0`` to ``k1`` of a run, none of them split, as arrays (their text a
    place in ``out`` and what :func:`_text` takes in ``pending``)."""
    plan = w.plan
    st = w.state
    n = k1 - k0
    offs = plan.offsets[run.first_move + k0:run.first_move + k1]
    comp = plan.compensated[offs]
    nom = plan.nominal[offs]
    present = run.present[k0:k1]
    pv = run.value[k0:k1]
    dec = run.decimals[k0:k1]
    dmin = w.dmin_mm
    # decimals of the last word of each axis, after each line (the writer's last_dec)
    idx = np.where(present, np.arange(1, n + 1)[:, None], 0)
    np.maximum.accumulate(idx, axis=0, out=idx)
    last = np.vstack([np.array(w.last_dec, dtype=np.int64)[None, :], np.maximum(dec, 1)])
    ld = np.take_along_axis(last, idx, axis=0)
    eff = np.where(present, dec, ld)
    d = np.maximum(dmin, eff)
    keep = np.maximum(eff, 1)
    held0 = np.array(w.state.held, dtype=float)
    ncomp = _round_units(comp.ravel(), d.ravel()).reshape(n, 3)
    scale = 10.0 ** d
    event = np.full((n, 3), np.nan)
    change = np.zeros((n, 3), dtype=bool)
    # a word of the line: rewritten when its number at d decimals differs
    nprog = np.rint(np.where(present, pv, 0.0) * scale).astype(np.int64)
    change[present] = ncomp[present] != nprog[present]
    event[present] = np.where(change[present], ncomp[present] / scale[present], pv[present])
    # an axis the line does not name: written when the number differs from the held one
    # at d decimals; inside a stretch of such lines the held number is the previous line's
    absent = ~present
    first = absent.copy()
    first[1:] &= present[:-1]
    nref = np.zeros((n, 3), dtype=np.int64)
    nref[1:] = ncomp[:-1]
    if first.any():
        r, a = np.nonzero(first)
        before = np.where(r > 0, event[np.maximum(r - 1, 0), a], held0[a])
        nref[r, a] = _round_units(before, d[r, a])
    change[absent] = ncomp[absent] != nref[absent]
    add = absent & change
    event[add] = ncomp[add] / scale[add]
    held = _ffill_nan(event, held0)
    st.record_many(np.arange(base + run.start + k0, base + run.start + k1) + 1, nom, held)
    st.held = held[-1].tolist()
    w.last_dec = ld[-1].tolist()
    w.out_motion = int(run.motion[k1 - 1])
    edited = change.any(axis=1)
    st.changed += int(edited.sum())
    i0 = run.start + k0
    pending.append((len(out), (run, k0, k1, lines[i0:i0 + n], comp, d, keep, change, ncomp,
                               w.file_sep)))
    out.append(None)


def _ffill_nan(event, initial):
    """``event`` (n, 3) with every NaN the last number before it (or ``initial``)."""
    n = event.shape[0]
    has = ~np.isnan(event)
    idx = np.where(has, np.arange(1, n + 1)[:, None], 0)
    np.maximum.accumulate(idx, axis=0, out=idx)
    full = np.vstack([initial[None, :], event])
    return np.take_along_axis(full, idx, axis=0)


def _text(run, k0, k1, contents, comp, d, keep, change, units, file_sep):
    """What :func:`.plain_bytes.stretch_text` takes for lines ``k0`` to ``k1`` of a run
    (``contents`` their ``(content, ending)``): unchanged lines stay as they were; changed
    lines with all three axis words and their new numbers' decimals not trimmed (and below
    :data:`_EXACT` units) are built as bytes (``rows``); the other changed lines one at a
    time (``other``: :func:`_assemble`, :func:`surfcomp.io.gcode.emitter._fmt`)."""
    edited = change.any(axis=1)
    present = run.present[k0:k1]
    plain = (present.all(axis=1)
             & ((d >= 1) & (d == keep) & (np.abs(units) < _EXACT) | ~change).all(axis=1)
             & np.isfinite(comp).all(axis=1))
    rows = np.flatnonzero(edited & plain)
    other = {}
    for k in np.flatnonzero(edited & ~plain).tolist():
        t = plain_groups(contents[k][0])
        nums = [_fmt(float(comp[k, a]), int(d[k, a]), int(keep[k, a])) if change[k, a]
                else None for a in (0, 1, 2)]
        other[k] = _assemble(t, nums, file_sep) + contents[k][1]
    return contents, run.size[k0:k1], units, d, change, rows, other


def _block_text(stretches):
    """The output texts of stretches (the arguments of :func:`_text` of each), built by
    one :func:`.plain_bytes.stretch_text` of all their lines."""
    if not stretches:
        return []
    parts = [_text(*a) for a in stretches]
    if len(parts) == 1:
        return [stretch_text(*parts[0])]
    contents = []
    other = {}
    rows = []
    for p in parts:
        off = len(contents)
        rows.append(p[5] + off)
        other.update((k + off, t) for k, t in p[6].items())
        contents.extend(p[0])
    bounds = np.cumsum([len(p[0]) for p in parts])
    cat = [np.concatenate([p[i] for p in parts]) for i in (1, 2, 3, 4)]
    return stretch_text(contents, *cat, np.concatenate(rows), other, bounds=bounds)


def _blank(s):
    return " " if s else ""


def _assemble(t, nums, file_sep):
    """A plain line from its :data:`surfcomp.io.gcode.plain.PLAIN` groups ``t`` (``""``
    for an absent word) with the axis numbers ``nums`` (text, or None to keep the word's):
    words of the line get their number replaced, the others are added next to the nearest
    axis word before them (or before the first one), as the line-by-line writer does."""
    g, s1, x, s2, y, s3, z, s4, f, tail = t
    if x and y and z:
        return "".join((
            "G" + g if g else "", s1,
            "X", x if nums[0] is None else nums[0], s2,
            "Y", y if nums[1] is None else nums[1], s3,
            "Z", z if nums[2] is None else nums[2], s4,
            "F" + f if f else "", tail))
    # separators: between the first two words, and between the first two axis words
    words = [(k, w) for k, w in enumerate((g, x, y, z, f)) if w]
    blanks = (s1, s2, s3, s4)
    general = (_blank("".join(blanks[words[0][0]:words[1][0]])) if len(words) > 1
               else file_sep)
    axes = [k for k, _w in words if 1 <= k <= 3]
    asep = _blank("".join(blanks[axes[0]:axes[1]])) if len(axes) > 1 else general
    parts = ["G" + g if g else "", s1]
    pending = []
    anchor = None           # where words after the last axis word go
    for a, w in enumerate((x, y, z)):
        s = nums[a]
        if not w:
            if s is None:
                pass
            elif anchor is not None:
                parts.insert(anchor, asep + "XYZ"[a] + s)
                anchor += 1
            else:
                pending.append("XYZ"[a] + s + asep)
        else:
            parts.extend(pending)
            pending = []
            parts.append("XYZ"[a] + (w if s is None else s))
            anchor = len(parts)
        parts.append(blanks[a + 1])
    parts.append("F" + f if f else "")
    parts.append(tail)
    return "".join(parts)
