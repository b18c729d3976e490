"""Batches (``lcp.solve_batch``, ``contact.solve_batch``, ``coulomb.rollout``): every answer is
bitwise the one-at-a-time call's, whatever the thread count; stacked and mixed-size input;
bad input refused before any work with the single call's exception, naming the argument and
the problem; empty batches; Ctrl-C; the GIL released."""

from __future__ import annotations

import multiprocessing
import os

import coulomb
import numpy as np
import pytest
from coulomb import contact, lcp
from coulomb.errors import (
    ArgumentTypeError,
    InvalidParameterError,
    NonFiniteError,
    ProblemTooLargeError,
    ShapeError,
)
from helpers import GIL_RELEASED, count_during
from hypothesis import given, settings
from hypothesis import strategies as st
from test_interrupt import BOUND, interrupt


def same(a: dict, b: dict, skip: tuple[str, ...] = ("solve_time",)) -> None:
    """Equal entry by entry to the last bit (arrays by value, dtype and shape)."""
    assert set(a) == set(b)
    for k in a:
        if k in skip:
            continue
        x, y = a[k], b[k]
        if isinstance(x, np.ndarray):
            assert isinstance(y, np.ndarray), k
            assert x.dtype == y.dtype and x.shape == y.shape, k
            assert x.tobytes() == y.tobytes(), k
        elif isinstance(x, float):
            assert np.float64(x).tobytes() == np.float64(y).tobytes(), k
        else:
            assert type(x) is type(y) and x == y, (k, x, y)


def spd(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    A = rng.standard_normal((n, n))
    return A @ A.T / max(n, 1) + np.eye(n), rng.standard_normal(n)


def nonsymmetric(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    # rows diagonally dominant: a P-matrix, one solution
    M = rng.uniform(-1.0, 1.0, (n, n))
    M[np.diag_indices(n)] = np.abs(M).sum(axis=1) + 0.5
    return M, 2.0 * rng.standard_normal(n)


@pytest.mark.parametrize("n", [1, 3, 30])
def test_a_stacked_lcp_batch_is_bitwise_the_single_solves(n):
    rng = np.random.default_rng(n)
    pairs = [spd(n, rng) if k % 2 else nonsymmetric(n, rng) for k in range(40)]
    Ms = np.stack([p[0] for p in pairs])
    qs = np.stack([p[1] for p in pairs])
    single = [lcp.solve(M, q) for M, q in pairs]
    for threads in (1, 2, None):
        out = lcp.solve_batch(Ms, qs, threads=threads)
        assert len(out) == len(pairs)
        for r, s in zip(out, single, strict=True):
            assert isinstance(r, lcp.LcpResult)
            same(r, s)
        assert out.z.shape == (40, n)
        assert out.z.tobytes() == np.stack([s.z for s in single]).tobytes()
        assert out.success.all()
        assert (out.error <= 1e-9).all()


def test_a_mixed_size_batch_is_bitwise_the_single_solves():
    rng = np.random.default_rng(7)
    sizes = [0, 1, 2, 5, 3, 17, 40, 300, 8]
    pairs = [spd(n, rng) for n in sizes]
    Ms, qs = [p[0] for p in pairs], [p[1] for p in pairs]
    for method, opts in (("lemke", {}), ("pgs", {"max_iter": 300}), ("lemke", {"polish": False})):
        single = [lcp.solve(M, q, method, **opts) for M, q in pairs]
        for threads in (1, 2, 3):
            out = lcp.solve_batch(Ms, qs, method, threads=threads, **opts)
            for r, s in zip(out, single, strict=True):
                same(r, s)
        z = out.z
        assert isinstance(z, list) and [len(v) for v in z] == sizes


@settings(max_examples=25, deadline=None)
@given(sizes=st.lists(st.integers(0, 12), max_size=30), seed=st.integers(0, 2**32 - 1),
       threads=st.integers(1, 4), scale=st.sampled_from([1e-8, 1.0, 1e8]),
       method=st.sampled_from(["lemke", "pgs"]))
def test_any_batch_is_bitwise_the_single_solves(sizes, seed, threads, scale, method):
    # over the class: sizes mixed, data scaled, SPD and nonsymmetric P-matrices, 1-4 threads
    rng = np.random.default_rng(seed)
    pairs = []
    for k, n in enumerate(sizes):
        M, q = spd(n, rng) if k % 2 else nonsymmetric(n, rng)
        pairs.append((scale * M, scale * q))
    opts = {"max_iter": 50} if method == "pgs" else {}
    out = lcp.solve_batch([p[0] for p in pairs], [p[1] for p in pairs], method,
                          threads=threads, **opts)
    assert len(out) == len(pairs)
    for r, (M, q) in zip(out, pairs, strict=True):
        same(r, lcp.solve(M, q, method, **opts))


def test_enumeration_and_warm_starts_per_problem():
    rng = np.random.default_rng(3)
    pairs = [nonsymmetric(4, rng) for _ in range(6)]
    Ms, qs = np.stack([p[0] for p in pairs]), np.stack([p[1] for p in pairs])
    enum = lcp.solve_batch(Ms, qs, "enumerate", threads=2)
    for r, (M, q) in zip(enum, pairs, strict=True):
        same(r, lcp.solve(M, q, "enumerate"))
    cold = lcp.solve_batch(Ms, qs)
    warm = lcp.solve_batch(Ms, qs, warm_start=cold)
    for r, c, (M, q) in zip(warm, cold, pairs, strict=True):
        same(r, lcp.solve(M, q, warm_start=c.basis))
        assert r.warm_start == "accepted" and r.pivots == 0
        assert r.z.tobytes() == c.z.tobytes() or np.allclose(r.z, c.z, rtol=1e-12, atol=1e-15)


def test_failures_and_long_messages_are_those_of_the_single_solves():
    # the core keeps a message in a fixed slot of bytes, a longer one whole beside it: both
    # kinds, in every chunk, read back as the single solve's text
    rng = np.random.default_rng(12)
    pairs = []
    for k in range(64):
        if k % 3 == 0:  # no solution: Lemke ends on a ray
            pairs.append((-(1.0 + k) * np.eye(3), -1.0 - np.abs(rng.standard_normal(3))))
        else:
            pairs.append(spd(3, rng))
    spd_only = [p for k, p in enumerate(pairs) if k % 3]
    for method, opts, some in (("lemke", {}, pairs), ("pgs", {"max_iter": 3}, spd_only)):
        Ms, qs = np.stack([p[0] for p in some]), np.stack([p[1] for p in some])
        single = [lcp.solve(M, q, method, **opts) for M, q in some]
        lengths = {len(s.message.encode()) for s in single}
        assert min(lengths) <= 56 and (method == "pgs" or max(lengths) > 56), lengths
        for threads in (1, 2):
            out = lcp.solve_batch(Ms, qs, method, threads=threads, **opts)
            assert out.message == [s.message for s in single]
            assert not out.success.all()
            for r, s in zip(out, single, strict=True):
                same(r, s)
    probs = [contact_problem(3, 3, rng) for _ in range(8)]
    for opts in ({"max_iter": 1}, {}):
        single = [contact.solve(W, q, mu, 3, "nsgs", **opts) for W, q, mu in probs]
        out = contact.solve_batch([p[0] for p in probs], [p[1] for p in probs],
                                  [p[2] for p in probs], 3, "nsgs", threads=2, **opts)
        assert out.message == [s.message for s in single]
        for r, s in zip(out, single, strict=True):
            same(r, s)


def test_options_are_those_of_the_single_solve():
    rng = np.random.default_rng(4)
    pairs = [spd(5, rng) for _ in range(4)]
    Ms, qs = np.stack([p[0] for p in pairs]), np.stack([p[1] for p in pairs])
    out = lcp.solve_batch(Ms, qs, settings=coulomb.PGSSettings(max_iter=7, relaxation=1.3))
    for r, (M, q) in zip(out, pairs, strict=True):
        same(r, lcp.solve(M, q, "pgs", max_iter=7, relaxation=1.3))
    cover = np.arange(1.0, 6.0)
    out = lcp.solve_batch(Ms, qs, covering_vector=cover, engine="tableau")
    for r, (M, q) in zip(out, pairs, strict=True):
        same(r, lcp.solve(M, q, covering_vector=cover, engine="tableau"))


def test_lcp_validation_names_the_argument_and_the_problem():
    rng = np.random.default_rng(5)
    Ms = np.stack([spd(3, rng)[0] for _ in range(5)])
    qs = rng.standard_normal((5, 3))
    bad = Ms.copy()
    bad[3, 1, 2] = np.nan
    with pytest.raises(NonFiniteError, match=r"Ms\[3\]"):
        lcp.solve_batch(bad, qs)
    with pytest.raises(ShapeError, match="qs"):
        lcp.solve_batch(Ms, qs[:, :2])
    with pytest.raises(ShapeError, match="4"):
        lcp.solve_batch(Ms, qs[:4])
    with pytest.raises(ShapeError, match=r"Ms\[1\]"):
        lcp.solve_batch([Ms[0], np.ones((2, 3))], [qs[0], qs[1]])
    with pytest.raises(ShapeError, match=r"qs\[1\]"):
        lcp.solve_batch([Ms[0], Ms[1]], [qs[0], np.ones(4)])
    with pytest.raises(InvalidParameterError, match="tol"):
        lcp.solve_batch(Ms, qs, tol=2.0)
    with pytest.raises(InvalidParameterError, match="threads"):
        lcp.solve_batch(Ms, qs, threads=0)
    with pytest.raises(ArgumentTypeError, match="threads"):
        lcp.solve_batch(Ms, qs, threads=1.5)
    with pytest.raises(InvalidParameterError, match="problem 2"):
        lcp.solve_batch(Ms, qs, warm_start=[[0], [1], [7], None, None])
    with pytest.raises(ShapeError, match="warm_start"):
        lcp.solve_batch(Ms[:2], qs[:2], warm_start=lcp.solve_batch(Ms, qs))
    with pytest.raises(ArgumentTypeError, match="Ms"):
        lcp.solve_batch("not a batch", qs)


def test_empty_batches():
    out = lcp.solve_batch(np.zeros((0, 3, 3)), np.zeros((0, 3)))
    assert len(out) == 0 and list(out) == [] and out.z.shape == (0, 3)
    assert out.success.shape == (0,) and out.error.shape == (0,)
    assert len(lcp.solve_batch([], [])) == 0
    assert len(contact.solve_batch([], [], [])) == 0
    assert coulomb.rollout([], 1.0, 1e-3) == []


def contact_problem(nc: int, dim: int, rng: np.random.Generator):
    n = dim * nc
    J = rng.standard_normal((n, n + 2))
    W = J @ J.T / (n + 2) + 0.1 * np.eye(n)
    q = rng.standard_normal(n)
    mu = rng.uniform(0.0, 1.0, nc)
    return W, q, mu


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("method", ["nsgs", "lemke", "prox"])
def test_a_contact_batch_is_bitwise_the_single_solves(dim, method):
    rng = np.random.default_rng(dim)
    probs = [contact_problem(1 + k % 5, dim, rng) for k in range(12)]
    single = [contact.solve(W, q, mu, dim, method) for W, q, mu in probs]
    for threads in (1, 2):
        out = contact.solve_batch([p[0] for p in probs], [p[1] for p in probs],
                                  [p[2] for p in probs], dim, method, threads=threads)
        for r, s in zip(out, single, strict=True):
            assert isinstance(r, contact.ContactResult)
            same(r, s)
    # stacked, one mu for all
    probs = [contact_problem(4, dim, rng) for _ in range(9)]
    Ws = np.stack([p[0] for p in probs])
    qs = np.stack([p[1] for p in probs])
    out = contact.solve_batch(Ws, qs, 0.3, dim, method, threads=2)
    for r, (W, q, _) in zip(out, probs, strict=True):
        same(r, contact.solve(W, q, 0.3, dim, method))
    assert out.impulse.shape == (9, 4, dim)


def test_contact_batch_options_and_anisotropy_per_problem():
    rng = np.random.default_rng(11)
    probs = [contact_problem(3, 3, rng) for _ in range(5)]
    Ws, qs = np.stack([p[0] for p in probs]), np.stack([p[1] for p in probs])
    mus = [p[2] for p in probs]
    mus[2] = np.column_stack([mus[2], 0.5 * mus[2]])  # anisotropic (nc, 2)
    init = [None, np.ones((3, 3)), None, None, np.zeros(9)]
    out = contact.solve_batch(Ws, qs, mus, 3, relaxation=0.9, initial=init, order="symmetric")
    for i, r in enumerate(out):
        same(r, contact.solve(Ws[i], qs[i], mus[i], 3, relaxation=0.9, initial=init[i],
                              order="symmetric"))
    rows = np.stack([p[2] for p in probs])
    out = contact.solve_batch(Ws, qs, rows, 3, settings=coulomb.NSGSSettings(max_iter=5))
    for i, r in enumerate(out):
        same(r, contact.solve(Ws[i], qs[i], rows[i], 3, max_iter=5))


def test_contact_validation_names_the_problem():
    rng = np.random.default_rng(12)
    probs = [contact_problem(2, 3, rng) for _ in range(4)]
    Ws, qs = np.stack([p[0] for p in probs]), np.stack([p[1] for p in probs])
    mus = np.stack([p[2] for p in probs])
    bad = mus.copy()
    bad[2, 1] = -0.5
    with pytest.raises(InvalidParameterError, match="problem 2"):
        contact.solve_batch(Ws, qs, bad, 3)
    bad = Ws.copy()
    bad[1, 0, 0] = np.inf
    with pytest.raises(NonFiniteError, match="problem 1"):
        contact.solve_batch(bad, qs, 0.5, 3)
    with pytest.raises(ShapeError, match="problem 3"):
        contact.solve_batch(list(Ws), [*list(qs[:3]), np.ones(5)], list(mus), 3)
    with pytest.raises(InvalidParameterError, match="dim"):
        contact.solve_batch(Ws, qs, 0.5, 4)
    with pytest.raises(ShapeError, match=r"problem 1: initial .* got a scalar"):
        contact.solve_batch(Ws, qs, 0.5, 3, initial=[None, 1.0] + [None] * (len(qs) - 2))
    with pytest.raises(InvalidParameterError, match="order"):
        contact.solve_batch(Ws, qs, 0.5, 3, order=[1, 0])


def ball(v0: tuple[float, float], mu: float, e: float) -> coulomb.Scene:
    s = coulomb.Scene(dim=2)
    floor = s.add(coulomb.HalfSpace((0.0, 0.0), (0.0, 1.0)))
    b = s.add(coulomb.Particle(mass=1.0, position=(0.0, 0.3), velocity=v0))
    s.contact(s.attach(b, coulomb.Disk(radius=0.05)), floor, mu=mu, e=e)
    return s


def box_drop(tilt: float) -> coulomb.Scene:
    s = coulomb.Scene(dim=3)
    floor = s.add(coulomb.HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    c, sn = np.cos(tilt / 2), np.sin(tilt / 2)
    body = s.add(coulomb.RigidBody3D(mass=1.0, inertia=np.eye(3) / 6,
                                     position=(0.0, 0.0, 0.6), orientation=(c, sn, 0.0, 0.0)))
    s.contact(s.attach(body, coulomb.Box((0.25, 0.25, 0.25))), floor, mu=0.5, e=0.0)
    return s


def same_trajectory(a: coulomb.Trajectory, b: coulomb.Trajectory) -> None:
    for name in ("t", "q", "v", "kinetic_energy", "potential_energy", "min_gap", "active",
                 "iterations", "contact_impulse", "contact_step", "fallback", "status"):
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert x.shape == y.shape and (x.tobytes() == y.tobytes() if x.dtype != object
                                       else list(x) == list(y)), name
    assert a.stopped == b.stopped


def test_a_rollout_is_bitwise_the_single_runs():
    scenes = [ball((0.5 * k, -1.0), 0.1 * k, 0.25 * (k % 4)) for k in range(6)]
    scenes += [box_drop(0.1 * k) for k in range(3)]
    single = [s.simulate(0.4, 1e-3, record_every=2) for s in scenes]
    assert single[1].q.tobytes() != single[2].q.tobytes()
    for threads in (1, 2, None):
        out = coulomb.rollout(scenes, 0.4, 1e-3, threads=threads, record_every=2)
        assert len(out) == len(scenes)
        for r, s in zip(out, single, strict=True):
            assert isinstance(r, coulomb.Trajectory)
            same_trajectory(r, s)


def test_rollout_validation_names_the_scene():
    good = ball((0.0, 0.0), 0.2, 0.0)
    with pytest.raises(InvalidParameterError, match="scene 1"):
        coulomb.rollout([good, coulomb.Scene(dim=2)], 1.0, 1e-3)
    with pytest.raises(InvalidParameterError, match="h"):
        coulomb.rollout([good], 1.0, -1e-3)
    with pytest.raises(InvalidParameterError, match="drift"):
        coulomb.rollout([good, good], 1.0, 1e-3, drift="sideways")
    with pytest.raises(ArgumentTypeError, match="scenes"):
        coulomb.rollout([good, "ball"], 1.0, 1e-3)
    # each run's states fit the memory budget alone, the two together do not
    with pytest.raises(ProblemTooLargeError, match="2 scenes"):
        coulomb.rollout([good, good], 15_000.0, 1e-3)


def test_a_batch_releases_the_gil():
    rng = np.random.default_rng(0)
    Ms = np.stack([spd(30, rng)[0] for _ in range(3000)])
    qs = rng.standard_normal((3000, 30))
    out, count = count_during(lambda: lcp.solve_batch(Ms, qs, threads=1))
    assert out.success.all()
    assert count > GIL_RELEASED


@pytest.mark.parametrize("call", [
    "M, q = murty(40); coulomb.lcp.solve_batch([M] * 4, [q] * 4, covering_vector=np.ones(40), "
    "max_pivots=10**9)",
    "W, q = redundant(100); coulomb.contact.solve_batch([W, W], [q, q], 0.5, 3, tol=1e-300, "
    "max_iter=10**9)",
    "coulomb.rollout([pile(10), pile(10)], 10000.0, 1e-3, record_every=100)",
    # solved on the calling thread: one problem, or one thread asked for
    "M, q = murty(40); coulomb.lcp.solve_batch([M], [q], covering_vector=np.ones(40), "
    "max_pivots=10**9)",
    "W, q = redundant(100); coulomb.contact.solve_batch([W, W], [q, q], 0.5, 3, tol=1e-300, "
    "max_iter=10**9, threads=1)",
])
def test_ctrl_c_stops_a_batch(call):
    got = interrupt(call)
    assert got["outcome"] == "KeyboardInterrupt", got
    assert got["latency"] < BOUND, got


def test_a_light_batch_runs_on_the_calling_thread_and_a_heavy_one_on_the_pool():
    # thread names in a fresh process: the pool's threads are "coulomb-batch-<i>"
    code = (
        "import os, numpy as np, coulomb\n"
        "def names():\n"
        "    t = f'/proc/{os.getpid()}/task'\n"
        "    return sorted(open(f'{t}/{k}/comm').read().strip() for k in os.listdir(t))\n"
        "M = np.stack([np.eye(3) * 2] * 200); q = -np.ones((200, 3))\n"
        "coulomb.lcp.solve_batch(M, q, threads=2)\n"
        "coulomb.lcp.solve_batch(M[:1], q[:1], threads=2)\n"
        "coulomb.lcp.solve_batch(np.stack([np.eye(3)] * 20000), -np.ones((20000, 3)), "
        "threads=1)\n"
        "light = names()\n"
        "coulomb.lcp.solve_batch(np.stack([np.eye(3)] * 20000), -np.ones((20000, 3)), "
        "threads=2)\n"
        "pool = lambda ns: sum('coulomb-batch' in n for n in ns)\n"
        "print(pool(light), pool(names()))\n"
    )
    if not os.path.isdir("/proc/self/task"):
        pytest.skip("needs /proc to name the threads")
    import subprocess
    import sys
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    assert out.stdout.split() == ["0", "2"], out


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_a_forked_child_runs_batches_on_its_own_threads():
    # the parent's pools exist before the fork; their threads do not follow the child
    rng = np.random.default_rng(9)
    Ms = np.stack([spd(4, rng)[0] for _ in range(64)])
    qs = rng.standard_normal((64, 4))
    parent = lcp.solve_batch(Ms, qs, threads=2)
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(1) as pool:
        z = pool.apply_async(_child_batch, (Ms, qs)).get(timeout=60)
    assert z.tobytes() == parent.z.tobytes()


def _child_batch(Ms: np.ndarray, qs: np.ndarray) -> np.ndarray:
    return np.asarray(lcp.solve_batch(Ms, qs, threads=2).z)
