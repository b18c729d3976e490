#!/usr/bin/env python3
"""Write the FCLib subset's problems (local, and global ones reduced by
``coulomb.contact.assemble``) as raw little-endian files for ``benches/nsgs/survey.rs``.

Each file ``NAME.fc`` holds: dim and nc as two u64, then W dense row-major
((dim nc)^2 f64), q (dim nc f64) and mu (nc f64).

    python benches/nsgs/dump_fclib.py /tmp/fclib-raw
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np


def main() -> None:
    from coulomb.io import read_fclib

    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    default = Path(__file__).resolve().parents[3] / "shared" / "data"
    root = Path(os.environ.get("COULOMB_DATA", default))
    for f in sorted((root / "fclib").glob("**/*.hdf5")):
        try:
            p = read_fclib(f)
        except Exception as exc:  # refused kinds (rolling) are skipped
            print(f"skip {f.name}: {type(exc).__name__}", file=sys.stderr)
            continue
        W = p.W.toarray() if hasattr(p.W, "toarray") else np.asarray(p.W)
        name = p.name.replace(".hdf5", "")
        with open(out / f"{name}.fc", "wb") as fh:
            np.array([p.dim, p.mu.shape[0]], dtype="<u8").tofile(fh)
            np.ascontiguousarray(W, dtype="<f8").tofile(fh)
            np.asarray(p.q, dtype="<f8").tofile(fh)
            np.asarray(p.mu, dtype="<f8").tofile(fh)
        print(name, p.dim, p.mu.shape[0])


if __name__ == "__main__":
    main()
