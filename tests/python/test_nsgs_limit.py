"""What NSGS returns when it stops at its sweep limit after a move along a drift.

A drift move ([`rust/contact/nsgs/extrapolate.rs`]) jumps to the first change of case along
a stalled drift; beyond its first eight moves it goes only to a change of case the sweeps
left could not reach. Such a move raises the error until the sweeps converge again from the
changed case, and late in the budget they may not have the time: the solve then returns its
best measured iterate (with that iterate's velocity and measures), not the last.
"""

from __future__ import annotations

import re

import numpy as np
import scipy.sparse as sp
from coulomb.contact import solve
from coulomb.io import read_fclib

FC2D = "fclib/Extra2D/siconos/fc2d_granularflowonwall/fc2d_granularflowonwall_02020_00213.hdf5"


def test_a_solve_ended_after_a_late_move_returns_its_best_measured_iterate(data_dir) -> None:
    p = read_fclib(data_dir / FC2D)
    r = solve(p.W, p.q, p.mu, dim=p.dim, method="nsgs", tol=1e-8, max_iter=10_000)
    assert r.status == "iteration_limit" and not r.success
    assert r.iterations == 10_000
    m = re.search(r"\(the best measured iterate, after sweep (\d+)\)$", r.message)
    assert m is not None, r.message
    assert 64 <= int(m.group(1)) < 10_000
    # the velocity reported is that of the impulses returned
    W = p.W.toarray() if sp.issparse(p.W) else np.asarray(p.W)
    impulse = np.asarray(r.impulse).ravel()
    u = W @ impulse + np.asarray(p.q)
    scale = np.abs(W) @ np.abs(impulse) + np.abs(np.asarray(p.q))
    assert np.all(np.abs(u - np.asarray(r.velocity).ravel()) <= 1e-12 * (scale + 1e-300))
    # the sweeps' last iterate, after moves late in the budget, measured 3.9e-6
    assert r.scaled_error < 1e-6, r.message
