# SPDX-License-Identifier: LGPL-2.1-or-later
"""App tests need FreeCAD headless; import it once for the whole folder.

No skipping: when FreeCAD is missing these tests fail, because CI must run them.
"""

from surfcomp.app import fcenv

fcenv.import_freecad()
