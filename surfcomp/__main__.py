"""``python3 -m surfcomp``: the batch command line."""

import sys

from .cli import main

sys.exit(main())
