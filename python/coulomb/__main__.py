"""``python -m coulomb``: the ``coulomb`` command line (see :mod:`coulomb.cli`)."""

from __future__ import annotations

from .cli import main

if __name__ == "__main__":
    raise SystemExit(main())
