# SPDX-License-Identifier: LGPL-2.1-or-later
"""Paths of the addon's resources (computed here, never in Init files: those are exec'd)."""

import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESOURCES = os.path.join(ROOT, "resources")


def icon(name):
    """Absolute path of an icon in resources/icons."""
    return os.path.join(RESOURCES, "icons", name)
