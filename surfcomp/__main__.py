# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp``: the batch command line."""

import sys

from .cli import main

sys.exit(main())
