# SPDX-License-Identifier: LGPL-2.1-or-later
"""Surface compensation: deviations, the mask filter, correction fields, the corrected face and its
checks, regions of faces, program offsets."""
