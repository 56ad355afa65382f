# SPDX-License-Identifier: LGPL-2.1-or-later
"""Look inside a FreeCAD document (.FCStd) before FreeCAD opens it (no FreeCAD needed).

An FCStd is a zip archive whose ``Document.xml`` lists the objects and the Python modules
of their proxies. FreeCAD's own parser expands XML entities, so a hostile ``Document.xml``
(a "billion laughs" entity bomb) makes it run for minutes and eat gigabytes, and a proxy
module name makes it import that module. Every route that opens a user's FCStd reads
``Document.xml`` here first: size limits, no document type declaration, no entities.
"""

import xml.parsers.expat
import zipfile

from ..errors import InputError

#: largest Document.xml accepted, uncompressed (FreeCAD documents of large assemblies are a
#: few tens of MB; the shapes live in separate .brp members)
MAX_DOCUMENT_XML = 256 * 1024 * 1024
#: largest compression ratio of Document.xml (XML compresses about 5-20 times)
MAX_RATIO = 200


class _Refused(Exception):
    pass


def _refuse(*_args):
    raise _Refused("it declares a document type or entities (DTD), which FreeCAD documents "
                   "never do")


def read_document_xml(path):
    """The bytes of ``Document.xml`` of the FCStd ``path``, checked.

    Raises
    ------
    InputError
        Not a zip archive, no ``Document.xml``, too large, or not plain XML.
    """
    try:
        with zipfile.ZipFile(path) as z:
            try:
                info = z.getinfo("Document.xml")
            except KeyError:
                raise InputError("not a FreeCAD document (no Document.xml inside)",
                                 file=path) from None
            if info.file_size > MAX_DOCUMENT_XML or (
                    info.compress_size and info.file_size / info.compress_size > MAX_RATIO
                    and info.file_size > 1024 * 1024):
                raise InputError("Document.xml is implausibly large (%d bytes, %d compressed; "
                                 "expected at most %d MB): refusing to open it"
                                 % (info.file_size, info.compress_size,
                                    MAX_DOCUMENT_XML // 2 ** 20), file=path)
            with z.open(info) as fh:
                data = fh.read(MAX_DOCUMENT_XML + 1)
    except (OSError, zipfile.BadZipFile, RuntimeError) as exc:
        raise InputError("not a FreeCAD document (%s)" % exc, file=path) from exc
    if len(data) > MAX_DOCUMENT_XML:
        raise InputError("Document.xml is larger than it says: refusing to open it", file=path)
    return data


def parse_document(path):
    """Parse ``Document.xml`` with entities refused.

    Returns
    -------
    dict
        ``objects``: list of ``(name, type)``; ``modules``: sorted proxy module names
        (``<Python module=...>``); ``files``: sorted names of the other documents its links
        point to (``<XLink file=...>``, as FreeCAD saved them: relative to the document's
        folder, or absolute).
    """
    data = read_document_xml(path)
    objects, modules, files = [], set(), set()
    depth = {"Objects": 0}

    def start(tag, attrs):
        if tag == "Objects":
            depth["Objects"] += 1
        elif tag == "Object" and depth["Objects"] and "type" in attrs:
            objects.append((attrs.get("name"), attrs.get("type")))
        elif tag == "Python" and attrs.get("module"):
            modules.add(attrs["module"])
        elif tag.startswith("XLink") and attrs.get("file"):
            files.add(attrs["file"])

    def end(tag):
        if tag == "Objects":
            depth["Objects"] -= 1

    parser = xml.parsers.expat.ParserCreate()
    parser.StartDoctypeDeclHandler = _refuse
    parser.EntityDeclHandler = _refuse
    parser.UnparsedEntityDeclHandler = _refuse
    parser.ExternalEntityRefHandler = _refuse
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(data, True)
    except _Refused as exc:
        raise InputError("Document.xml is not a plain FreeCAD document: %s" % exc,
                         file=path) from None
    except xml.parsers.expat.ExpatError as exc:
        raise InputError("Document.xml is damaged: %s" % xml.parsers.expat.ErrorString(
            exc.code), file=path, line=exc.lineno) from None
    except (LookupError, ValueError) as exc:  # the declared encoding cannot be decoded
        raise InputError("Document.xml is damaged: its XML declaration names an encoding "
                         "that cannot be read (%s; FreeCAD writes UTF-8)" % exc,
                         file=path) from None
    return {"objects": objects, "modules": sorted(modules), "files": sorted(files)}
