"""The Rust core releases the GIL while it solves."""

from __future__ import annotations

import sys
import threading

import numpy as np
from coulomb import lcp


def test_lemke_releases_the_gil():
    rng = np.random.default_rng(0)
    n = 800
    A = rng.standard_normal((n, n))
    M = A @ A.T / n + np.eye(n)  # dense SPD
    q = rng.standard_normal(n)
    counter = [0]
    seen = {}

    def solve():
        # The readings straddle the call into the Rust core: the arrays are already float64
        # and C-contiguous, so solve() does almost no Python work of its own.
        seen["before"] = counter[0]
        seen["result"] = lcp.solve(M, q)
        seen["after"] = counter[0]

    # A short switch interval: a thread that holds the GIL through a long C call lets the
    # main thread in only at its few bytecode boundaries, each for ~0.1 ms (calibration on
    # this machine: a GIL-holding C call of similar length let the main thread count to at
    # most ~600; this solve, which releases the GIL, to 100 000 - 200 000).
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    try:
        t = threading.Thread(target=solve)
        t.start()
        while t.is_alive():
            counter[0] += 1
        t.join()
    finally:
        sys.setswitchinterval(old)
    r = seen["result"]
    assert r.success is True
    assert r.error <= 1e-10
    assert seen["after"] - seen["before"] > 20_000
