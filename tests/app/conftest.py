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


@pytest.fixture(scope="session")
def cam_example(tmp_path_factory):
    """The example's finishing Job before and after the compensation replaces the nominal
    (tests/app/cam_example.py), built once for the modules that check it; they read only
    what the build recorded (test_path_regen.py's restore, which changes its document, has
    a build of its own)."""
    import FreeCAD

    from tests.app import cam_example as example

    built = example.build(tmp_path_factory.mktemp("cam_example"))
    yield built
    FreeCAD.closeDocument(built.doc.Name)
