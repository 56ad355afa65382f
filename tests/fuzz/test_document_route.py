# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate DOC.FCStd MEAS --object O --replace --save OUT.FCStd`` on bad input.

The document (``inputs.document_bytes``) holds ``Nominal`` (the example face) and
``Helper`` (a Python feature). Modules the document names are in test_hostile_modules.py.
"""

import pytest

from . import inputs as I
from .harness import Case, run_case

DOC = I.put("d.FCStd", I.document_bytes)
MEAS = I.put("m.csv", I.csv)
BASE = I.setup(DOC, MEAS)
SAVE = ("--save", "out.FCStd")


def doc(name, *extra, setup=BASE, document="d.FCStd", meas="m.csv", save=SAVE,
        obj=("--object", "Nominal"), **kw):
    return Case(name, ("compensate", document, meas) + tuple(obj) + ("--replace",)
                + tuple(save) + tuple(extra) + ("--quiet",), setup=setup, **kw)


def with_meas(data):
    return I.setup(DOC, I.put("m.csv", data))


def with_doc(data):
    return I.setup(MEAS, I.put("d.FCStd", data))


LINKED = I.setup(I.folder("v"), I.put("v/d.FCStd", I.document_bytes), I.put("v/m.csv", I.csv),
                 I.link("vlink", "v"))

CASES = [
    # outputs over inputs
    doc("save-is-the-input", save=("--save", "d.FCStd"), file="d.FCStd",
        says=("--save would overwrite the input document (--overwrite-input allows it)",)),
    doc("save-through-symlinked-folder-onto-the-input", setup=LINKED, document="v/d.FCStd",
        meas="v/m.csv", save=("--save", "vlink/d.FCStd"), file="vlink/d.FCStd",
        says=("would overwrite the input document", "through a link")),
    doc("save-hard-link-of-the-input", setup=I.setup(BASE, I.hardlink("h.FCStd", "d.FCStd")),
        save=("--save", "h.FCStd"), file="h.FCStd", says=("would overwrite the input",)),
    doc("save-symlink-onto-the-measurements", setup=I.setup(BASE, I.link("m.FCStd", "m.csv")),
        save=("--save", "m.FCStd"), file="m.FCStd",
        says=("--save would overwrite the input MEASUREMENTS",)),
    doc("gcode-onto-the-measurements", "--gcode", "m.csv", file="m.csv",
        says=("--gcode would overwrite the input MEASUREMENTS",)),
    # outputs over each other
    doc("gcode-equals-save", "--gcode", "out.FCStd", file="out.FCStd",
        says=("--save and --gcode name the same file",)),
    doc("gcode-hard-link-of-save", "--gcode", "o.ngc",
        setup=I.setup(BASE, I.put("out.FCStd", "old"), I.hardlink("o.ngc", "out.FCStd")),
        file="o.ngc", says=("--save and --gcode name the same file",)),
    # all or nothing
    doc("save-is-an-existing-folder", setup=I.setup(BASE, I.folder("out.FCStd")),
        file="out.FCStd", says=("--save is a folder",)),
    doc("gcode-without-a-path-job", "--gcode", "new/o.ngc", save=("--save", "new/out.FCStd"),
        setup=I.setup(BASE, I.folder("new")),
        says=("no Path jobs use the compensation",)),
    doc("save-in-proc", save=("--save", "/proc/out.FCStd"), file="/proc/out.FCStd"),
    doc("save-not-an-fcstd", save=("--save", "out.txt"), file="out.txt",
        says=("must end in .FCStd",)),
    doc("o-with-the-document-route", "-o", "c.step", says=("--output cannot be combined",)),
    doc("replace-without-save", save=(), says=("need --save",)),
    doc("without-object", obj=(), file="d.FCStd", says=("--object NAME is required",)),
    doc("nominal-is-a-step", setup=I.setup(MEAS, I.put("n.step", I.step_text)),
        document="n.step", file="n.step", says=("NOMINAL must be an .FCStd",)),
    # unbounded values
    doc("refine=0", "--refine", "0", says=("--refine 0",)),
    doc("mask=9999", "--mask", "9999", says=("--mask 9999",)),
    doc("max-offset=nan", "--max-offset", "nan", says=("--max-offset nan",)),
    doc("tip-radius=nan", "--tip-radius", "nan", says=("--tip-radius nan",)),
    doc("one-deviation-1e308", setup=with_meas(lambda: I.csv_with({(7, "dev"): "1e308"})),
        file="m.csv", line=I.line_of(7), says=("is this the right file?",)),
    doc("all-deviations-5mm", setup=with_meas(lambda: I.csv_all("dev", "5")), file="m.csv",
        line=I.line_of(0), says=("--deviation-units um",)),
    # malformed measurements
    doc("csv-text-in-a-number", setup=with_meas(lambda: I.csv_with({(1, "z_nom"): "abc"})),
        file="m.csv", line=I.line_of(1), says=("abc",)),
    doc("csv-empty", setup=with_meas(""), file="m.csv"),
    doc("csv-binary-garbage", setup=with_meas(bytes(range(256)) * 64), file="m.csv"),
    doc("csv-utf-16", setup=with_meas(lambda: I.csv().encode("utf-16")), file="m.csv"),
    doc("csv-header-only", setup=with_meas(I.HEADER + "\n"), file="m.csv", line=1),
    doc("csv-missing", meas="gone.csv", file="gone.csv"),
    # malformed documents
    doc("fcstd-not-a-zip", setup=with_doc(b"PK\x03\x04 but no zip"), file="d.FCStd",
        says=("not a FreeCAD document",)),
    doc("fcstd-without-document-xml", setup=with_doc(lambda: I.rezip(drop=("Document.xml",))),
        file="d.FCStd", says=("no Document.xml",)),
    doc("fcstd-bad-xml", setup=with_doc(lambda: I.rezip(lambda t: t[:len(t) // 3])),
        file="d.FCStd", says=("Document.xml is damaged",)),
    doc("fcstd-billion-laughs", setup=with_doc(lambda: I.rezip(I.BILLION_LAUGHS.encode())),
        file="d.FCStd", says=("DTD",)),
    doc("fcstd-oversized-document-xml", setup=with_doc(lambda: I.rezip(
        lambda t: t.replace("<Document ", "<!--" + " " * (8 << 20) + "-->\n<Document ", 1))),
        file="d.FCStd", says=("implausibly large",)),
    doc("fcstd-unknown-object-type", setup=with_doc(lambda: I.rezip(
        lambda t: t.replace('type="App::FeaturePython"', 'type="Nope::Feature"'))),
        file="d.FCStd", says=("did not restore",)),
    doc("fcstd-no-such-object", obj=("--object", "Nope"), file="d.FCStd",
        says=("no object 'Nope'",)),
    doc("fcstd-object-without-faces", obj=("--object", "Helper"), file="d.FCStd",
        says=("has no faces",)),
    # accepted
    doc("good-document", rc=0, writes=("out.FCStd",)),
]


@pytest.mark.parametrize("case", CASES, ids=str)
def test_case(case, tmp_path):
    run_case(case, tmp_path / "case")
