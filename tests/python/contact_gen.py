"""Generated friction-contact problems and an independent check of Coulomb's law, for the
property suite (test_contact_properties.py) and its long campaign (docs/properties.md).

Problems: ``W = G^T M^-1 G`` from a random G (``m x dim nc``; ``m < dim nc`` gives a singular
W, redundant contacts) and a diagonal M with masses spread over six decades. Planted problems
choose per contact a state of the law -- separating (``r = 0``, ``u_n > 0``), sticking
(``u = 0``, ``||r_t|| < mu r_n``) or sliding (``u_n = 0``, ``r_t = -mu r_n u_t / ||u_t||``) --
and set ``q = u* - W r*``, so a solution is known to exist. Random problems draw q freely and
may have none. Units: impulses are multiplied by ``a = 10^ka`` and velocities by
``b = 10^kb`` (``W -> (b/a) W``, ``q -> b q``).

The check (:func:`law_violation`) is written here from the law itself, not from coulomb's
measures: it recomputes ``u = W r + q`` and tests, per contact, Signorini's condition, the
cone, and sticking or sliding, each relative to the contact's own scales (velocity: the
magnitudes of the terms ``u_i`` is summed from; impulse: its impulse or the impulse that
would cancel that velocity through ``W_ii``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MODERATE_MU = (0.0, 0.1, 0.5, 1.0, 2.0, 10.0)
MU_CLASSES = (*MODERATE_MU, 1e4, 1e8, 1e12)


@dataclass
class Problem:
    W: np.ndarray
    q: np.ndarray
    mu: np.ndarray
    dim: int
    planted: bool
    r_star: np.ndarray | None


def generate(seed: int, dim: int, planted: bool, ka: int = 0, kb: int = 0,
             mu_class: float | None = None, mu_choices: tuple[float, ...] = MU_CLASSES,
             sliding: bool = True) -> Problem:
    """One problem (see the module notes); ``mu_class`` fixes mu for every contact, otherwise
    each contact draws one of ``mu_choices``; without ``sliding`` a planted contact drawn to
    slide sticks instead (same draws)."""
    rng = np.random.default_rng(seed)
    nc = int(rng.integers(1, 7))
    n = dim * nc
    m = int(max(1, n + rng.choice([-2, 0, 3])))
    G = rng.standard_normal((m, n))
    minv = 10.0 ** rng.uniform(-3, 3, m)
    W = G.T @ (minv[:, None] * G)
    W = 0.5 * (W + W.T)
    if mu_class is None:
        mu = rng.choice(mu_choices, nc)
    else:
        mu = np.full(nc, float(mu_class))
    r_star = None
    if planted:
        r_star = np.zeros(n)
        u_star = np.zeros(n)
        for i in range(nc):
            s = slice(i * dim, (i + 1) * dim)
            mode = rng.integers(3)
            t = rng.standard_normal(dim - 1)
            t /= max(np.linalg.norm(t), 1e-300)
            if mode == 0:  # separating
                u_star[s] = np.concatenate([[rng.uniform(0.1, 1.0)], rng.standard_normal(dim - 1)])
            elif mode == 1 or not sliding:  # sticking
                rn = rng.uniform(0.1, 1.0)
                frac = rng.uniform(0.0, 0.9)
                r_star[s] = np.concatenate([[rn], -min(mu[i], 2.0) * frac * rn * t])
            else:  # sliding
                rn = rng.uniform(0.1, 1.0)
                r_star[s] = np.concatenate([[rn], -mu[i] * rn * t])
                u_star[s] = np.concatenate([[0.0], rng.uniform(0.1, 1.0) * t])
        q = u_star - W @ r_star
    else:
        q = rng.standard_normal(n)
    a, b = 10.0**ka, 10.0**kb
    return Problem(W * (b / a), q * b, mu, dim, planted,
                   None if r_star is None else r_star * a)


def perturb_ulp(p: Problem, seed: int) -> Problem:
    """The same problem with each entry of W (kept symmetric) and q moved by at most one unit
    in the last place, in the same units: the rounding a change of units by 10^k brings to the
    normalized data (every method runs on the problem rescaled by powers of two), without any
    change of units."""
    rng = np.random.default_rng(seed)
    eps = np.finfo(float).eps
    k = rng.integers(-1, 2, p.W.shape)
    k = np.triu(k) + np.triu(k, 1).T
    W = p.W * (1.0 + k * eps)
    q = p.q * (1.0 + rng.integers(-1, 2, p.q.shape) * eps)
    return Problem(W, q, p.mu, p.dim, p.planted, p.r_star)


def law_violation(W: np.ndarray, q: np.ndarray, mu: np.ndarray, dim: int,
                  r: np.ndarray, polygon: bool = False) -> float:
    """The worst violation of Signorini's condition and Coulomb's law by impulses r, each
    relative to its contact's scales (0 at an exact solution; see the module notes). With
    ``polygon`` (the 3D polyhedral cone, whose sliding impulses snap to facets) only
    Signorini's condition and the cone are checked."""
    r = np.asarray(r, dtype=float).reshape(-1)
    u = W @ r + q
    terms = np.abs(W) @ np.abs(r) + np.abs(q)
    worst = 0.0
    for i in range(len(mu)):
        s = slice(i * dim, (i + 1) * dim)
        ri, ui = r[s], u[s]
        V = float(np.max(terms[s]))
        block = float(np.max(np.abs(W[s, s])))
        R = max(float(np.max(np.abs(ri))), V / block if block > 0 else 0.0)
        if V == 0.0 and R == 0.0:
            continue
        V = V if V > 0 else 1.0
        R = R if R > 0 else 1.0
        rn, un = ri[0], ui[0]
        rt, ut = ri[1:], ui[1:]
        nrt, nut = float(np.linalg.norm(rt)), float(np.linalg.norm(ut))
        slip = nut / V
        gap = (mu[i] * max(rn, 0.0) - nrt) / R
        checks = [
            -rn / R,  # pushes, never pulls
            -un / V,  # no approach
            min(rn / R, un / V),  # Signorini: one of them is zero
            -gap,  # in the cone
        ]
        if not polygon:
            checks.append(min(gap, slip))  # sticks, or slides on the cone's boundary
        if nut > 0 and not polygon:
            # a sliding impulse opposes the slip (its misalignment weighted by the slip)
            checks.append((nrt + float(rt @ ut) / nut) / R * slip)
        worst = max(worst, *checks)
    return float(worst)


@dataclass
class Counts:
    """Outcome counts of a campaign, per method."""

    cases: int = 0
    successes: int = 0
    false_successes: int = 0
    planted: int = 0
    planted_successes: int = 0
    planted_moderate: int = 0
    planted_moderate_successes: int = 0
    status_changes: int = 0
    hard_cases: int = 0
    hard_status_changes: int = 0
    ulp_status_changes: int = 0
    ulp_hard_status_changes: int = 0
    worst_false: float = 0.0


@dataclass
class Flip:
    """One status change of a campaign: the method, the problem (seed, dim, planted, class),
    its units and the other units (or ``"ulp"``: the one-ulp rounding control), and per solve
    the status, iterations and message."""

    method: str
    seed: int
    dim: int
    hard: bool
    units: tuple[int, int]
    other: tuple[int, int] | str
    statuses: tuple[str, str]
    iterations: tuple[int, int]
    messages: tuple[str, str]


METHODS = ("nsgs", "prox", "lemke")
FALSE = 1e-6  # a success whose law violation exceeds this (relative) is false
TOL = 1e-8


def solve(p: Problem, method: str):
    from coulomb import contact

    kw = {"max_iter": 2000} if method == "nsgs" else {}
    return contact.solve(p.W, p.q, p.mu, dim=p.dim, method=method, tol=TOL, **kw)


def campaign(n: int, start: int = 0, ulp: bool = False,
             flips: list[Flip] | None = None) -> dict[str, Counts]:
    """n generated problems (2 in 3 planted, both dims, units 10^-8..10^8, mu 0..1e12), each
    solved by every method in its units and in other units (status compared); with ``ulp``,
    also with its data moved by one ulp in its own units (:func:`perturb_ulp`, status
    compared: the rounding control of the unit changes). Each status change is appended to
    ``flips`` when given."""
    out = {m: Counts() for m in METHODS}
    for seed in range(start, start + n):
        rng = np.random.default_rng(10_000 + seed)
        dim = 2 + seed % 2
        planted = seed % 3 != 2
        ka, kb, ka2, kb2 = (int(k) for k in rng.integers(-8, 9, 4))
        p = generate(seed, dim, planted, ka, kb)
        p2 = generate(seed, dim, planted, ka2, kb2)
        p3 = perturb_ulp(p, 20_000 + seed) if ulp else None
        for method in METHODS:
            c = out[method]
            res = solve(p, method)
            res2 = solve(p2, method)
            res3 = solve(p3, method) if p3 is not None else res
            c.cases += 1
            c.planted += planted
            hard = bool(p.mu.max() > 10 or not planted)
            if flips is not None:
                for other, res_o in (((ka2, kb2), res2), ("ulp", res3)):
                    if res.status != res_o.status:
                        flips.append(Flip(method, seed, dim, hard, (ka, kb), other,
                                          (res.status, res_o.status),
                                          (res.iterations, res_o.iterations),
                                          (res.message, res_o.message)))
            # mu above 10 somewhere (conditioned like mu) or no solution planted: a verdict
            # near the tolerance may differ with the rounding of the scaled data
            if hard:
                c.hard_cases += 1
                c.hard_status_changes += res.status != res2.status
                c.ulp_hard_status_changes += res.status != res3.status
            else:
                c.status_changes += res.status != res2.status
                c.ulp_status_changes += res.status != res3.status
            moderate = planted and p.mu.max() <= 10
            c.planted_moderate += moderate
            if res.success:
                c.successes += 1
                c.planted_successes += planted
                c.planted_moderate_successes += moderate
                v = law_violation(p.W, p.q, p.mu, dim, res.impulse,
                                  polygon=method == "lemke" and dim == 3)
                if not v <= FALSE:
                    c.false_successes += 1
                    c.worst_false = max(c.worst_false, v)
    return out


def moderate_changes(method: str, n: int, dim: int = 3, seed: int = 1) -> tuple[int, int]:
    """Status changes on n planted problems with mu <= 10 (the property test's class): each
    solved as generated, in other units 10^ka, 10^kb (ka, kb in -8..8), and with its data
    moved by one ulp (:func:`perturb_ulp`); returns (changes with the units, changes by one
    ulp)."""
    rng = np.random.default_rng(seed)
    units = ulps = 0
    for _ in range(n):
        s = int(rng.integers(0, 2**31))
        ka, kb = (int(k) for k in rng.integers(-8, 9, 2))
        base = generate(s, dim, True, mu_choices=MODERATE_MU)
        r = solve(base, method)
        units += r.status != solve(generate(s, dim, True, ka, kb, mu_choices=MODERATE_MU),
                                   method).status
        ulps += r.status != solve(perturb_ulp(base, s), method).status
    return units, ulps


@dataclass
class StickingGain:
    """NSGS with and without its sticking-set solve on the same problems (see
    :func:`sticking_gain`)."""

    plain: int = 0  # solved by plain sweeps (sticking=False)
    default: int = 0  # solved by the default (the sticking-set solve)
    fewer: int = 0  # solved by the default only, or in fewer sweeps
    lost: list[int] | None = None  # seeds plain sweeps solve and the default does not
    false: int = 0  # successes (either way) that violate the law by more than FALSE


def sticking_gain(n: int) -> StickingGain:
    """NSGS (tol 1e-8, 2000 sweeps) with and without the sticking-set solve on the planted
    3D problems of seeds 0..n-1 with mu <= 10, every success checked by
    :func:`law_violation`."""
    from coulomb import contact

    g = StickingGain(lost=[])
    for seed in range(n):
        p = generate(seed, 3, True, mu_choices=MODERATE_MU)
        default, plain = (contact.solve(p.W, p.q, p.mu, 3, tol=TOL, max_iter=2000, sticking=s)
                          for s in (True, False))
        for r in (default, plain):
            if r.success and not law_violation(p.W, p.q, p.mu, 3, r.impulse) <= FALSE:
                g.false += 1
        g.plain += plain.success
        g.default += default.success
        g.fewer += default.success and (not plain.success
                                        or default.iterations < plain.iterations)
        if plain.success and not default.success:
            g.lost.append(seed)
    return g


if __name__ == "__main__":  # docs/properties.md: N [START] [--flips] | N --moderate | N --sticking
    import sys

    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    if "--moderate" in sys.argv:  # N planted problems, mu <= 10, 3D: prox's changes
        print(moderate_changes("prox", int(args[0]) if args else 3000))
        raise SystemExit(0)
    if "--sticking" in sys.argv:  # N planted 3D problems, mu <= 10: NSGS with and without
        print(sticking_gain(int(args[0]) if args else 1000))
        raise SystemExit(0)
    n = int(args[0]) if args else 3000
    start = int(args[1]) if len(args) > 1 else 0
    changes: list[Flip] = []
    for method, c in campaign(n, start, ulp=True, flips=changes).items():
        print(f"{method}: {c}")
    if "--flips" in sys.argv:  # every status change, one a line
        for f in changes:
            print(f)
