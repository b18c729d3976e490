"""An independent Lemke's method in exact rational arithmetic: the oracle for the tests.

Tableau form ``w - M z - d z0 = q`` with covering vector ``d`` (default all ones). The
tableau kept is ``[B^-1 q | B^-1]``; a column of the entering variable is ``B^-1 A_e``. The
ratio test is the lexicographic minimum of ``[B^-1 q | B^-1]_i / a_i`` over ``a_i > 0``,
except that z0 leaves first whenever its row ties on the first component (the value). Every
number is a :class:`fractions.Fraction` (floats are converted exactly), so the pivot path
and the answer are those of the mathematics, not of a floating-point implementation.

Pivots are counted as coulomb counts them: the first pivot (z0 enters) included.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction


@dataclass
class ExactLemkeResult:
    status: str  # "solved", "ray_termination" or "pivot_limit"
    z: list[Fraction]
    w: list[Fraction]
    pivots: int
    basis: list[int]  # indices i with z_i basic at the end, ascending


def _frac(x: object) -> Fraction:
    return x if isinstance(x, Fraction) else Fraction(x)  # exact for floats and ints


def _lexmin(rows: list[int], T: list[list[Fraction]], a: list[Fraction]) -> int:
    """The row whose ``T[i] / a[i]`` is lexicographically smallest (a[i] > 0 or < 0 alike)."""
    return min(rows, key=lambda i: [t / a[i] for t in T[i]])


def lemke(
    M: Sequence[Sequence[object]],
    q: Sequence[object],
    d: Sequence[object] | None = None,
    max_pivots: int = 100_000,
) -> ExactLemkeResult:
    n = len(q)
    Mf = [[_frac(x) for x in row] for row in M]
    qf = [_frac(x) for x in q]
    df = [Fraction(1)] * n if d is None else [_frac(x) for x in d]
    if any(x <= 0 for x in df):
        raise ValueError("covering vector must be positive")
    z0 = 2 * n  # variable labels: w_i -> i, z_i -> n + i, z0 -> 2n

    def result(status: str, basis: list[int], T: list[list[Fraction]], pivots: int):
        z = [Fraction(0)] * n
        for r, var in enumerate(basis):
            if n <= var < 2 * n:
                z[var - n] = T[r][0]
        w = [qf[i] + sum(Mf[i][j] * z[j] for j in range(n)) for i in range(n)]
        zb = sorted(v - n for v in basis if n <= v < 2 * n)
        return ExactLemkeResult(status, z, w, pivots, zb)

    basis = list(range(n))
    T = [[qf[i]] + [Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    if all(x >= 0 for x in qf):
        return result("solved", basis, T, 0)

    def column(var: int) -> list[Fraction]:
        # A_e for w_j is e_j, for z_j is -M[:, j], for z0 is -d; return B^-1 A_e.
        if var < n:
            return [T[i][1 + var] for i in range(n)]
        col = [-Mf[k][var - n] for k in range(n)] if var < 2 * n else [-x for x in df]
        return [sum(T[i][1 + k] * col[k] for k in range(n) if col[k]) for i in range(n)]

    def pivot(r: int, a: list[Fraction]) -> None:
        pr = [t / a[r] for t in T[r]]
        T[r] = pr
        for i in range(n):
            if i != r and a[i]:
                f = a[i]
                T[i] = [ti - f * pi for ti, pi in zip(T[i], pr, strict=True)]

    # First pivot: z0 enters, the row of the lexicographically smallest (q_i, e_i) / d_i leaves.
    a = column(z0)
    r = min(range(n), key=lambda i: [t / df[i] for t in T[i]])
    leaving = basis[r]
    pivot(r, a)
    basis[r] = z0
    pivots = 1
    entering = n + leaving  # the complement of w_r
    while pivots < max_pivots:
        a = column(entering)
        rows = [i for i in range(n) if a[i] > 0]
        if not rows:
            return result("ray_termination", basis, T, pivots)
        theta = min(T[i][0] / a[i] for i in rows)
        ties = [i for i in rows if T[i][0] / a[i] == theta]
        z0_rows = [i for i in ties if basis[i] == z0]
        r = z0_rows[0] if z0_rows else _lexmin(ties, T, a)
        leaving = basis[r]
        pivot(r, a)
        basis[r] = entering
        pivots += 1
        if leaving == z0:
            return result("solved", basis, T, pivots)
        entering = leaving + n if leaving < n else leaving - n
    return result("pivot_limit", basis, T, pivots)


def murty(n: int) -> tuple[list[list[int]], list[int]]:
    """Murty's exponential example: M upper triangular, 1 on the diagonal and 2 above;
    ``q_i = -(2^(n+1) - 2^(i+1))``. Lemke with covering vector ones takes 2^n pivots."""
    M = [[1 if i == j else (2 if j > i else 0) for j in range(n)] for i in range(n)]
    q = [-(2 ** (n + 1) - 2 ** (i + 1)) for i in range(n)]
    return M, q
