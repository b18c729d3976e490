"""Instructions per problem of an LCP batch at n = 3 on one thread, by callgrind.

Run: ``python benches/batch_callgrind.py`` (about a minute; needs valgrind). Each of two runs
generates the same 6,001 problems and solves the first 2,001 or all 6,001 of them with
``coulomb.lcp.solve_batch(..., threads=1)`` under ``valgrind --tool=callgrind
--separate-threads=yes``; the difference between the runs, divided by 4,000, is a problem's
cost on the worker thread and on the calling thread, with every fixed cost (start-up, the
generation, the pool) cancelled. Instruction counts do not depend on the machine's load.
"""

from __future__ import annotations

import glob
import os
import subprocess
import sys
import tempfile

SMALL, LARGE = 2001, 6001


def child(count: int) -> None:
    import coulomb
    import numpy as np

    n = 3
    rng = np.random.default_rng(7)
    A = rng.standard_normal((LARGE, n, n))
    Ms = np.ascontiguousarray(A @ A.transpose(0, 2, 1) / n + np.eye(n))
    qs = rng.standard_normal((LARGE, n))
    r = coulomb.lcp.solve_batch(Ms[:count], qs[:count], threads=1)
    assert r.success.all()


def totals(count: int, folder: str) -> dict[str, int]:
    out = os.path.join(folder, f"cg.{count}")
    subprocess.run(
        ["valgrind", "--tool=callgrind", "--separate-threads=yes",
         f"--callgrind-out-file={out}.%p", sys.executable, __file__, "--child", str(count)],
        check=True, capture_output=True,
        # numpy's BLAS threads spin while they wait, for as long as the run lasts: one
        # BLAS thread keeps them out of the count
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"})
    found = {}
    for path in sorted(glob.glob(f"{out}.*-*")):
        thread = path.rsplit("-", 1)[1]
        with open(path) as f:
            for line in f:
                if line.startswith(("summary:", "totals:")):
                    found[thread] = int(line.split()[1])
                    break
    return found


def main() -> None:
    if sys.argv[1:2] == ["--child"]:
        child(int(sys.argv[2]))
        return
    with tempfile.TemporaryDirectory() as folder:
        small, large = totals(SMALL, folder), totals(LARGE, folder)
    per = {t: (large[t] - small.get(t, 0)) / (LARGE - SMALL) for t in large}
    # thread 01 is the calling (Python) thread; the others are the pool's
    calling = per.pop("01")
    pool = sum(per.values())
    print(f"per problem: {pool:,.0f} instructions on the pool's threads, {calling:,.0f} on the "
          f"calling thread, {pool + calling:,.0f} in all "
          f"(by thread: {', '.join(f'{t}: {v:,.0f}' for t, v in sorted(per.items()))})")

if __name__ == "__main__":
    main()
