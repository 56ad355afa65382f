# SPDX-License-Identifier: LGPL-2.1-or-later
"""SHA-256 of input files for reports."""

import hashlib


def sha256_file(path, chunk=1 << 20):
    """Hex SHA-256 of the file at ``path``."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(chunk), b""):
            h.update(block)
    return h.hexdigest()
