"""Every public entry point refuses bad input before any work with a ``coulomb.errors``
exception (a ``ValueError``; the ``ArgumentTypeError`` ones are also ``TypeError``) whose
message names the argument: no numpy or builtin message that does not say which argument, no
OverflowError, no silent truncation (``max_iter=2.5``), no silently ignored option
(``relaxation`` with Lemke), no None turned into NaN, and no allocation the input sizes past
the memory budget.

``python tests/python/test_bad_input.py`` prints how many cases are clear (the right class
and the argument named); run it with an older coulomb first on ``PYTHONPATH`` to compare.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import coulomb
import numpy as np
import pytest
from coulomb import contact, errors, lcp

try:
    import scipy.sparse as sp
except ImportError:  # pragma: no cover - scipy is a test dependency
    sp = None

EYE = np.eye(2)
Q = np.array([-1.0, 1.0])
W2 = np.eye(2) / 2
Q2 = np.array([-3.0, 1.0])
E = errors.InvalidParameterError
T = errors.ArgumentTypeError
S = errors.ShapeError
N = errors.NonFiniteError
L = errors.ProblemTooLargeError


def ball() -> coulomb.Scene:
    s = coulomb.Scene(dim=2)
    b = s.add(coulomb.Particle(mass=1.0, position=(0.0, 0.1)))
    f = s.add(coulomb.HalfSpace())
    s.contact(s.attach(b, coulomb.Point()), f, mu=0.2, e=0.5)
    return s


def model(gap: Callable[[np.ndarray], float] = lambda q: q[1]) -> coulomb.Model:
    return coulomb.Model(dim=2, mass_matrix=np.eye(2), q0=[0.0, 1.0],
                         force=lambda q, v, t: np.array([0.0, -9.81]),
                         contacts=[coulomb.GapContact(gap=gap, normal_jacobian=lambda q: [0, 1],
                                                      tangent_jacobian=lambda q: [[1, 0]],
                                                      mu=0.2)])


def bad_csc():
    m = sp.csc_matrix(np.eye(2))
    m.indices[1] = 7  # out of range after construction: scipy's tocsr would read past it
    return m


# (case, call, expected class, words the message must contain)
CASES: list[tuple[str, Callable[[], object], type, tuple[str, ...]]] = [
    # coulomb.lcp.solve
    ("lcp M ragged", lambda: lcp.solve([[1.0, 2.0], [3.0]], Q), S, ("M",)),
    ("lcp q ragged", lambda: lcp.solve(EYE, [[1.0], [2.0, 3.0]]), S, ("q",)),
    ("lcp M None", lambda: lcp.solve(None, Q), T, ("M",)),
    ("lcp M with None entry", lambda: lcp.solve([[None, 0.0], [0.0, 1.0]], Q), T, ("M", "None")),
    ("lcp q None", lambda: lcp.solve(EYE, None), T, ("q",)),
    ("lcp q with None entry", lambda: lcp.solve(EYE, [None, 1.0]), T, ("q", "None")),
    ("lcp M string", lambda: lcp.solve("abc", Q), T, ("M",)),
    ("lcp tol string", lambda: lcp.solve(EYE, Q, tol="a"), T, ("tol",)),
    ("lcp tol None", lambda: lcp.solve(EYE, Q, tol=None), T, ("tol",)),
    ("lcp tol 1e300", lambda: lcp.solve(EYE, Q, tol=1e300), E, ("tol", "(0, 1)")),
    ("lcp tol 1", lambda: lcp.solve(EYE, Q, tol=1.0), E, ("tol",)),
    ("lcp tol inf", lambda: lcp.solve(EYE, Q, tol=math.inf), E, ("tol",)),
    ("lcp max_pivots 1e30", lambda: lcp.solve(EYE, Q, max_pivots=10**30), E, ("max_pivots",)),
    ("lcp max_pivots 2.5", lambda: lcp.solve(EYE, Q, max_pivots=2.5), T, ("max_pivots",)),
    ("lcp max_pivots bool", lambda: lcp.solve(EYE, Q, max_pivots=True), T, ("max_pivots",)),
    ("lcp restarts 1e9", lambda: lcp.solve([[-1.0]], [-1.0], restarts=10**9), E,
     ("restarts", "1000")),
    ("lcp restarts 1e30", lambda: lcp.solve(EYE, Q, restarts=10**30), E, ("restarts",)),
    ("lcp restarts -1", lambda: lcp.solve(EYE, Q, restarts=-1), E, ("restarts",)),
    ("lcp restarts 2.0", lambda: lcp.solve(EYE, Q, restarts=2.0), T, ("restarts",)),
    ("lcp max_iter 1e30", lambda: lcp.solve(EYE, Q, "pgs", max_iter=10**30), E, ("max_iter",)),
    ("lcp max_iter 2.5", lambda: lcp.solve(EYE, Q, "pgs", max_iter=2.5), T, ("max_iter",)),
    ("lcp max_iter '5'", lambda: lcp.solve(EYE, Q, "pgs", max_iter="5"), T, ("max_iter",)),
    ("lcp max_iter 0", lambda: lcp.solve(EYE, Q, "pgs", max_iter=0), E, ("max_iter",)),
    ("lcp relaxation with lemke", lambda: lcp.solve(EYE, Q, relaxation=5), E, ("relaxation",)),
    ("lcp initial with lemke", lambda: lcp.solve(EYE, Q, initial=[0.0, 0.0]), E, ("initial",)),
    ("lcp max_iter with lemke", lambda: lcp.solve(EYE, Q, max_iter=5), E, ("max_iter",)),
    ("lcp covering_vector with pgs",
     lambda: lcp.solve(EYE, Q, "pgs", covering_vector=[1.0, 1.0]), E, ("covering_vector",)),
    ("lcp restarts with enumerate", lambda: lcp.solve(EYE, Q, "enumerate", restarts=3), E,
     ("restarts",)),
    ("lcp relaxation 5 pgs", lambda: lcp.solve(EYE, Q, "pgs", relaxation=5.0), E,
     ("relaxation",)),
    ("lcp relaxation string", lambda: lcp.solve(EYE, Q, "pgs", relaxation="x"), T,
     ("relaxation",)),
    ("lcp initial with NaN", lambda: lcp.solve(EYE, Q, "pgs", initial=[np.nan, 0.0]), N,
     ("initial",)),
    ("lcp initial None entry", lambda: lcp.solve(EYE, Q, "pgs", initial=[None, 0.0]), T,
     ("initial",)),
    ("lcp polish string", lambda: lcp.solve(EYE, Q, polish="yes"), T, ("polish",)),
    ("lcp engine unknown", lambda: lcp.solve(EYE, Q, engine="fast"), E, ("engine",)),
    ("lcp method unknown", lambda: lcp.solve(EYE, Q, "simplex"), E, ("method",)),
    ("lcp method None", lambda: lcp.solve(EYE, Q, None), E, ("method",)),
    ("lcp warm_start string", lambda: lcp.solve(EYE, Q, warm_start="01"), T, ("warm_start",)),
    ("lcp warm_start floats", lambda: lcp.solve(EYE, Q, warm_start=[0.5]), E, ("warm_start",)),
    ("lcp.check z ragged", lambda: lcp.check(EYE, Q, [[1.0], [1.0, 2.0]]), S, ("z",)),
    ("lcp.check z None", lambda: lcp.check(EYE, Q, None), T, ("z",)),
    # coulomb.contact.solve
    ("contact W ragged", lambda: contact.solve([[0.5, 0.0], [0.5]], Q2, 0.2, dim=2), S, ("W",)),
    ("contact W None", lambda: contact.solve(None, Q2, 0.2, dim=2), T, ("W",)),
    ("contact q None", lambda: contact.solve(W2, None, 0.2, dim=2), T, ("q",)),
    ("contact q with None", lambda: contact.solve(W2, [None, 1.0], 0.2, dim=2), T, ("q",)),
    ("contact mu None", lambda: contact.solve(W2, Q2, None, dim=2), T, ("mu",)),
    ("contact mu string", lambda: contact.solve(W2, Q2, "a", dim=2), T, ("mu",)),
    ("contact mu negative", lambda: contact.solve(W2, Q2, -0.1, dim=2), E, ("mu",)),
    ("contact dim 4", lambda: contact.solve(W2, Q2, 0.2, dim=4), E, ("dim",)),
    ("contact dim True", lambda: contact.solve(W2, Q2, 0.2, dim=True), E, ("dim",)),
    ("contact dim 2.0", lambda: contact.solve(W2, Q2, 0.2, dim=2.0), E, ("dim",)),
    ("contact tol string", lambda: contact.solve(W2, Q2, 0.2, dim=2, tol="a"), T, ("tol",)),
    ("contact tol None", lambda: contact.solve(W2, Q2, 0.2, dim=2, tol=None), T, ("tol",)),
    ("contact tol 1e300", lambda: contact.solve(W2, Q2, 0.2, dim=2, tol=1e300), E, ("tol",)),
    ("contact max_iter 2.5", lambda: contact.solve(W2, Q2, 0.2, dim=2, max_iter=2.5), T,
     ("max_iter",)),
    ("contact max_iter '5'", lambda: contact.solve(W2, Q2, 0.2, dim=2, max_iter="5"), T,
     ("max_iter",)),
    ("contact max_iter 1e30", lambda: contact.solve(W2, Q2, 0.2, dim=2, max_iter=10**30), E,
     ("max_iter",)),
    ("contact lemke max_iter 1e30",
     lambda: contact.solve(W2, Q2, 0.2, dim=2, method="lemke", max_iter=10**30), E,
     ("max_iter",)),
    ("contact relaxation 5", lambda: contact.solve(W2, Q2, 0.2, dim=2, relaxation=5), E,
     ("relaxation",)),
    ("contact relaxation with lemke",
     lambda: contact.solve(W2, Q2, 0.2, dim=2, method="lemke", relaxation=1.5), E,
     ("relaxation",)),
    ("contact facets with nsgs", lambda: contact.solve(W2, Q2, 0.2, dim=2, facets=8), E,
     ("facets",)),
    ("contact facets 1e6 lemke",
     lambda: contact.solve(np.eye(3), [-1.0, 0.0, 0.0], 0.2, dim=3, method="lemke",
                           facets=10**6), E, ("facets", "1024")),
    ("contact facets 2.5", lambda: contact.solve(W2, Q2, 0.2, dim=2, method="lemke",
                                                 facets=2.5), T, ("facets",)),
    ("contact eta string", lambda: contact.solve(W2, Q2, 0.2, dim=2, method="prox", eta="x"), T,
     ("eta",)),
    ("contact eta with nsgs", lambda: contact.solve(W2, Q2, 0.2, dim=2, eta=0.1), E, ("eta",)),
    ("contact initial scalar", lambda: contact.solve(W2, Q2, 0.2, dim=2, initial=1.0), S,
     ("initial", "got a scalar")),
    ("contact initial ragged", lambda: contact.solve(W2, Q2, 0.2, dim=2, initial=[[1], [1, 2]]),
     S, ("initial",)),
    ("contact order unknown", lambda: contact.solve(W2, Q2, 0.2, dim=2, order="sideways"), E,
     ("order",)),
    ("contact method unknown", lambda: contact.solve(W2, Q2, 0.2, dim=2, method="pgs"), E,
     ("method",)),
    # coulomb.contact.assemble / post_velocity
    ("assemble M ragged", lambda: contact.assemble([[1.0], [1.0, 2.0]], EYE, Q2), S, ("M",)),
    ("assemble G None", lambda: contact.assemble(EYE, None, Q2), T, ("G",)),
    ("assemble v_free None entry", lambda: contact.assemble(EYE, EYE, [None, 1.0]), T,
     ("v_free",)),
    ("post_velocity r None", lambda: contact.post_velocity(EYE, EYE, Q2, None), T,
     ("impulse",)),
    # coulomb.io readers
    ("read_siconos_lcp None", lambda: coulomb.io.read_siconos_lcp(None), T, ("path",)),
    ("read_siconos_fc 3", lambda: coulomb.io.read_siconos_fc(3), T, ("path",)),
    ("read_fclib None", lambda: coulomb.io.read_fclib(None), T, ("path",)),
    # Scene construction
    ("Scene dim 4", lambda: coulomb.Scene(dim=4), E, ("dim",)),
    ("Scene dim True", lambda: coulomb.Scene(dim=True), E, ("dim",)),
    ("Scene gravity None entry", lambda: coulomb.Scene(dim=2, gravity=[None, -9.81]), T,
     ("gravity",)),
    ("Scene gravity ragged", lambda: coulomb.Scene(dim=2, gravity=[[0.0], [1.0, 2.0]]), S,
     ("gravity",)),
    ("Particle mass None", lambda: coulomb.Scene(2).add(coulomb.Particle(mass=None)), T,
     ("mass",)),
    ("Particle mass string", lambda: coulomb.Scene(2).add(coulomb.Particle(mass="1")), T,
     ("mass",)),
    ("Particle position None entry",
     lambda: coulomb.Scene(2).add(coulomb.Particle(mass=1.0, position=[None, 0.0])), T,
     ("position",)),
    ("contact mu string", lambda: ball().contact_spheres(mu="a"), T, ("mu",)),
    # Scene.simulate
    ("simulate t_end None", lambda: ball().simulate(None, 1e-3), T, ("t_end",)),
    ("simulate h string", lambda: ball().simulate(1.0, "x"), T, ("h",)),
    ("simulate t_end/h 1e33", lambda: ball().simulate(1e30, 1e-3), E, ("t_end / h",)),
    ("simulate 1e9 s at 1e-3", lambda: ball().simulate(1e9, 1e-3), E, ("t_end / h", "10000")),
    ("simulate records over budget", lambda: ball().simulate(3e5, 1e-3), L,
     ("record_every",)),
    ("simulate max_iter 2.5", lambda: ball().simulate(0.01, 1e-3, max_iter=2.5), T,
     ("max_iter",)),
    ("simulate max_iter 1e30", lambda: ball().simulate(0.01, 1e-3, max_iter=10**30), E,
     ("max_iter",)),
    ("simulate tol 1e300", lambda: ball().simulate(0.01, 1e-3, tol=1e300), E, ("tol",)),
    ("simulate facets with nsgs", lambda: ball().simulate(0.01, 1e-3, facets=8), E,
     ("facets",)),
    ("simulate facets 1e6 lemke", lambda: ball().simulate(0.01, 1e-3, "lemke", facets=10**6),
     E, ("facets",)),
    ("simulate relaxation with lemke",
     lambda: ball().simulate(0.01, 1e-3, "lemke", relaxation=1.5), E, ("relaxation",)),
    ("simulate solver unknown", lambda: ball().simulate(0.01, 1e-3, "pgs"), E, ("solver",)),
    ("simulate record_every 0", lambda: ball().simulate(0.01, 1e-3, record_every=0), E,
     ("record_every",)),
    ("simulate record_every 2.5", lambda: ball().simulate(0.01, 1e-3, record_every=2.5), T,
     ("record_every",)),
    ("simulate warm_start string", lambda: ball().simulate(0.01, 1e-3, warm_start="no"), T,
     ("warm_start",)),
    ("simulate drift unknown", lambda: ball().simulate(0.01, 1e-3, drift="x"), E, ("drift",)),
    ("simulate gap_tolerance None", lambda: ball().simulate(0.01, 1e-3, gap_tolerance=None), T,
     ("gap_tolerance",)),
    # Model
    ("Model q0 None", lambda: coulomb.Model(dim=2, mass_matrix=EYE, q0=None), T, ("q0",)),
    ("Model q0 ragged", lambda: coulomb.Model(dim=2, mass_matrix=EYE, q0=[[0.0], [1.0, 2.0]]), S,
     ("q0",)),
    ("Model contact not a GapContact",
     lambda: coulomb.Model(dim=2, mass_matrix=EYE, q0=[0.0, 1.0], contacts=[object()]), T,
     ("contact 0",)),
    ("GapContact mu string",
     lambda: coulomb.Model(dim=2, mass_matrix=EYE, q0=[0.0, 1.0],
                           contacts=[coulomb.GapContact(gap=lambda q: q[1], mu="a")]), T,
     ("mu",)),
    ("Model gap returns NaN", lambda: model(lambda q: math.nan).simulate(0.01, 1e-3), N,
     ("gap function",)),
    ("Model simulate t_end/h 1e33", lambda: model().simulate(1e30, 1e-3), E, ("t_end / h",)),
    ("Model simulate max_iter 2.5", lambda: model().simulate(0.01, 1e-3, max_iter=2.5), T,
     ("max_iter",)),
    ("Model simulate facets with nsgs", lambda: model().simulate(0.01, 1e-3, facets=8), E,
     ("facets",)),
    # painleve, study
    ("PainleveRod mu None", lambda: coulomb.painleve.PainleveRod(mu=None), T, ("mu",)),
    ("PainleveRod m string", lambda: coulomb.painleve.PainleveRod(m="1"), T, ("m",)),
    ("painleve analyze theta None",
     lambda: coulomb.painleve.PainleveRod().analyze(None), T, ("theta",)),
    ("study sweep repeat 2.5", lambda: coulomb.study.sweep(lambda h: {"x": h}, {"h": [1.0]},
                                                          repeat=2.5), T, ("repeat",)),
    ("study sweep run None", lambda: coulomb.study.sweep(None, {"h": [1.0]}), T, ("run",)),
]

if sp is not None:
    CASES += [
        ("contact sparse W bad index", lambda: contact.solve(bad_csc(), Q2, 0.2, dim=2), S,
         ("W",)),
        ("contact lemke on 5000 contacts",
         lambda: contact.solve(sp.identity(15000, format="csr"), -np.ones(15000), 0.5, dim=3,
                               method="lemke"), L, ("budget", "facets")),
    ]


def classify(call: Callable[[], object], exc: type, words: tuple[str, ...]) -> str:
    """'clear' (the class expected and every word in the message), or what happened."""
    try:
        call()
    except BaseException as e:
        if not isinstance(e, errors.CoulombError):
            return f"unclear: {type(e).__name__}: {e}"
        if not isinstance(e, exc):
            return f"wrong class: {type(e).__name__}: {e}"
        missing = [w for w in words if w not in str(e)]
        return f"unclear: {type(e).__name__}: {e} (missing {missing})" if missing else "clear"
    return "accepted"


@pytest.mark.parametrize("case", [c[0] for c in CASES])
def test_bad_input_is_refused_naming_the_argument(case):
    _, call, exc, words = next(c for c in CASES if c[0] == case)
    with pytest.raises(exc) as info:
        call()
    assert isinstance(info.value, errors.CoulombError) and isinstance(info.value, ValueError)
    if isinstance(info.value, errors.ArgumentTypeError):
        assert isinstance(info.value, TypeError)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_a_coulomb_error_is_raised_before_any_work():
    # the options are checked before the solve: a bad option with a problem that would take
    # long (Murty's example, 2^20 pivots) returns at once
    n = 20
    M = np.triu(np.full((n, n), 2.0), 1) + np.eye(n)
    q = -(2.0 ** (n + 1) - 2.0 ** (np.arange(n) + 1))
    with pytest.raises(T):
        lcp.solve(M, q, covering_vector=np.ones(n), max_pivots=10**6, polish="no")


def test_memory_budget_is_settable_and_checked():
    old = coulomb.memory_budget()
    try:
        coulomb.set_memory_budget(2**20)
        with pytest.raises(L, match="budget"):
            contact.solve(np.eye(3 * 30), -np.ones(90), 0.5, dim=3, method="lemke", facets=16)
        with pytest.raises(E):
            coulomb.set_memory_budget(10)
    finally:
        coulomb.set_memory_budget(old)
    assert coulomb.memory_budget() == old


if __name__ == "__main__":
    outcome = {c[0]: classify(c[1], c[2], c[3]) for c in CASES}
    bad = {k: v for k, v in outcome.items() if v != "clear"}
    for k, v in bad.items():
        print(f"{k:40s} {v[:150]}")
    print(f"{len(CASES)} cases: {len(CASES) - len(bad)} clear, {len(bad)} not")
