# SPDX-License-Identifier: LGPL-2.1-or-later
"""App tests need FreeCAD headless; import it once for the whole folder.

No skipping: when FreeCAD is missing these tests fail, because CI must run them.
"""

import pytest

from surfcomp.app import fcenv

fcenv.import_freecad()


@pytest.fixture
def fresh_doc():
    """A new FreeCAD document, closed after the test."""
    import FreeCAD

    d = FreeCAD.newDocument("test")
    yield d
    FreeCAD.closeDocument(d.Name)
