r"""Frictional contact over a frozen Delassus matrix W.

Given ``nc`` contacts of dimension ``dim`` (2: normal and one tangent; 3: normal and two
tangents, normal first in every block), the contact-space matrix W (``(dim nc) x (dim nc)``,
symmetric positive semidefinite, e.g. ``G^T M^-1 G``) and the free contact velocity q
(including any restitution term), find impulses r and velocities ``u = W r + q`` such that, per
contact i,

.. code-block:: text

    K_i ∋ r_i  ⊥  u_i + mu_i ||u_{t,i}|| n  ∈ K_i^*,      K_i = { ||r_t|| <= mu_i r_n }

(De Saxcé's bipotential form). This is Signorini's condition ``0 <= r_n ⊥ u_n >= 0`` together
with Coulomb's law: either sticking (``u_t = 0``, ``||r_t|| <= mu r_n``) or sliding
(``r_t = -mu r_n u_t / ||u_t||``, the friction impulse opposing the slip).

>>> import numpy as np, coulomb
>>> # Stewart's (2000) inelastic contact step: m = 2, v_n = -3, v_t = 1, mu = 0.2
>>> r = coulomb.contact.solve(np.eye(2) / 2, [-3.0, 1.0], 0.2, dim=2)
>>> r.status, r.impulse.round(12).tolist(), r.velocity.round(12).tolist()
(Status.SOLVED, [[6.0, -1.2]], [[0.0, 0.4]])

Methods:

``"nsgs"`` (default)
    Nonsmooth Gauss-Seidel with the exact friction disk: contact after contact, the one-contact
    problem with the others frozen is solved (2D exactly by case split; 3D by a normal /
    tangential block descent whose tangential step is the exact disk-constrained quadratic,
    run to convergence on a contact nothing else acts on and two passes per sweep on the
    others, whose fixed points are the same exact local solutions), with relaxation and warm
    start.
    With anisotropic friction (an ellipse), the tangential step is the exact minimiser over
    the ellipse (the ellipse projection when the contact's tangential block is a multiple of
    the identity).
``"lemke"``
    Stewart and Trinkle's (1996) polyhedral-cone LCP: the friction disk of every frictional
    contact is replaced by the polygon of ``facets`` unit tangent directions in +/- pairs
    (default 8 in 3D; in 2D only 2, the directions +1 and -1, which is exact),
    ``z = (P_n, beta, lambda)`` solves
    ``0 <= z ⊥ A z + b >= 0`` by Lemke's method and the impulses are mapped back
    (``P_t = D beta``). Frictionless contacts carry only the normal unknown. The LCP is
    assembled in balanced units (the multiplier column and row scaled by each contact's
    ``W_nn``), so Lemke's relative pivot tests see every entry at W's scale: with the raw form,
    data of size 1e-10 lost their friction. In 2D the polygon is exact and ``success`` follows
    the rule below; in 3D ``success`` means the polyhedral LCP was solved (to ``tol`` by
    Lemke's rule, the LCP's own error is in ``message``); ``iterations`` counts Lemke's
    pivots and ``max_iter`` (if given) limits them. The measures below are still taken
    against the exact disk, so in 3D they reflect the facet approximation (they shrink as
    ``facets`` grows, not monotonically: a sliding contact's impulse snaps to a facet). With
    anisotropic friction the directions are scaled along the tangents so that the polygon is
    inscribed in the ellipse. With friction coefficients of 1e8 and more the LCP is
    conditioned like mu; when every Lemke path fails, the LCP with the cone rows of mu above
    1e2, then 1e4, capped there (a sticking contact) and with the sliding ones' unknowns in
    units of ``P_n`` is solved, and its answer is kept only if it solves the given LCP
    (``message`` says so; ``iterations`` counts every path's pivots).
``"prox"`` (the robust mode)
    A proximal-point semismooth Newton method on the natural map (Rust ``contact::prox``):
    each iteration is one Newton step on the proximal subproblem ``W + eta I`` centred at the
    current impulses, with a line search and ``eta`` adapted (``eta`` is relative to W's mean
    diagonal; default 0.1), restarted from NSGS sweeps when it makes no progress. In 2D, where
    the problem is exactly an LCP, the first such stall is met instead by Lemke's method on the
    contacts that push (grown by those that close), kept only if it passes on the whole problem
    (``message`` then says "2D LCP finish"; Rust ``contact::lcp_finish``): it solves the
    FCLib granular flow whose rounded W is slightly indefinite and singular. In 3D the first two
    stalls solve the polyhedral LCP (8, then 32 directions) on those contacts, up to 500 LCP
    unknowns: its answer is exact when no contact slides and is then kept ("3D polyhedral
    LCP finish"), and otherwise Newton restarts from it ("restarted k time(s) from the
    polyhedral LCP's answer"). For the
    problems where NSGS stalls at tight tolerances (redundant contacts, FCLib BoxesStack and
    OneObject). ``success`` follows the rule below;
    ``iterations`` counts Newton steps (each one sparse LU factorization); ``max_iter`` defaults
    to 200; ``initial`` warm-starts it.

The contact problem of a mechanism (mass matrix M, contact directions G, free velocity) is
built by :func:`assemble` and the velocity after the impulses given by :func:`post_velocity`.

Every method runs on the problem rescaled by powers of two (exact) so that q and W's diagonal
are of size one whatever the units, and every answer is measured on the original data
(W, q, mu). **Success has one rule for every method** (except the 3D polygon, above):
``success`` is True exactly when ``scaled_error <= tol`` **and**
``error_q <= max(tol, error_q_floor)``, and the iterative methods stop on that same test
(measuring ``error_q`` in your units even while they work in rescaled ones). The first keeps a
light body's contact from hiding behind heavy ones and does not depend on units; the second is
the figure peers (Siconos, FCLib) stop on, so an answer coulomb calls solved is solved by
theirs too, down to its rounding level ``error_q_floor``.

``scaled_error``
    The unit-consistent measure. Per contact, ``rho_i = 1 / W_nn,i`` (impulse per unit
    velocity; a contact with no normal stiffness takes the mean's) turns velocities into
    impulses, and two natural maps are taken in impulse units: De Saxcé's
    ``e_i = r_i - P_K(r_i - rho_i (u_i + mu_i ||u_t,i|| n))`` and Alart-Curnier's
    ``a_i = (r_n - max(0, r_n - rho_i u_n), r_t - P_D(mu_i r_n)(r_t - rho_i u_t))``, which
    takes Signorini's condition and the sticking / sliding law apart (De Saxcé's alone is blind
    for a large mu: ``mu ||u_t||`` hides an approaching contact, so with mu = 1e8 the answer
    r = 0 of a contact that must push looked solved). ``scaled_error`` is the worst contact's
    ``max(||e_i||, ||a_i||)`` divided by its own impulse scale
    ``max(||r_i||, rho_i ||(|W| |r| + |q|)_i||)``. A slip ``s = ||u_t,i||`` below its own
    rounding ``f = (n + 3) eps ||(|W| |r| + |q|)_t,i||`` counts as none (above it, as
    ``s - f^2/s``), so a sticking contact with mu up to 1e12 solved to rounding is solved in
    every unit system instead of turning ``mu`` times its rounding into an error. Multiplying
    impulse units by a and velocity units by b (``W -> (b/a) W``, ``q -> b q``) leaves it unchanged,
    and so this half of the verdict; ``error`` and ``error_q`` add velocities to impulses and
    change with the units, so neither decides alone (at W of order 1e-5 they accepted answers
    of a problem without solution; at W of order 1e8 an exact answer may miss
    ``error_q <= tol``, which ``error_q_floor`` allows for).

``error_q_floor``
    The rounding level of ``error_q`` at this answer,
    ``eps (4 ||r|| + ||(1 + mu_i) (k_i + 2) (|W| |r| + |q|)_i||) / ||q||`` with ``k_i`` the
    stored products of contact i's rows of ``W r``: the map's argument is formed from ``u``,
    whose rounding is at most ``(k_i + 2) eps`` times its terms (Higham 2002, sec. 3.1), ``mu``
    multiplying the tangential part. An ``error_q`` up to it counts as 0.

``error``
    The natural-map residual on De Saxcé's form (Acary and Brogliato 2008; De Saxcé and Feng 1991),
    ``||r - P_K(r - (u + mu ||u_t|| n))||_2 / max(||q||, ||r||, ||u||)``, with ``P_K`` the
    projection on the product of the Coulomb cones (divided by 1 instead when all three norms
    are below 1e-300). It is zero exactly at a solution.
    For a contact with anisotropic friction ``(mu_1, mu_2)``, with ``m = max(mu_1, mu_2)``
    and ``B = diag(1, mu_1 / m, mu_2 / m)``, the change of variables ``r = B r^``,
    ``u^ = B u`` maps the elliptic cone onto the isotropic cone ``K_m`` and keeps the power
    ``r . u``, so its part of the residual is
    ``r - B P_{K_m}(B^+ r - (u^ + m ||u^_t|| n))`` (``m ||u^_t||`` is the ellipse's support
    function ``sqrt((mu_1 u_t1)^2 + (mu_2 u_t2)^2)``; for ``mu_1 = mu_2`` it is the isotropic
    residual).
``error_q``
    The same residual divided by ``||q||`` (by 1 when ``||q|| < 1e-300``), as Acary et al.
    report it for FCLib.
``min_normal_impulse``
    ``min_i r_{n,i}``: negative means a contact pulls (infeasible).
``max_complementarity``
    ``max_i |r_{n,i} u_{n,i}|``: a contact both pushing and separating.
``cone_violation``
    ``max_i max(||r_{t,i}|| - mu_i r_{n,i}, 0)``: friction beyond the Coulomb cone
    (anisotropic contacts: ``||B^+ r_t|| - m r_n``).
``dissipation_violation``
    ``max_i max(0, r_{t,i} . u_{t,i})`` over sliding contacts: a sliding friction impulse must
    oppose the slip (maximal dissipation).
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _validate
from ._assembly import assemble, post_velocity
from ._result import Result
from ._status import Status
from .errors import InvalidInputError, InvalidParameterError, NonFiniteError, ShapeError
from .lcp import _as_array
from .settings import NSGSSettings, PolyhedralSettings, ProxSettings, accepts

__all__ = [
    "ContactBatchResult", "ContactResult", "assemble", "post_velocity", "solve", "solve_batch",
]

Method = Literal["nsgs", "lemke", "prox"]


class ContactResult(Result):
    """The answer of :func:`solve`.

    Attributes
    ----------
    impulse : ndarray, shape (nc, dim)
        The impulses r, contact by contact, normal component first.
    velocity : ndarray, shape (nc, dim)
        ``u = W r + q`` recomputed from the original data.
    success : bool
        True exactly when ``scaled_error <= tol`` and ``error_q <= max(tol, error_q_floor)``
        (for ``"lemke"`` in 3D: when the polyhedral LCP was solved).
    status : Status
        ``Status.SOLVED``, ``ITERATION_LIMIT`` (the budget was spent: ``max_iter`` sweeps, or
        every restart of ``"prox"`` stalled) or ``NUMERICAL_FAILURE``; each equals its
        string (``r.status == "solved"``).
    message : str
        One line for a person.
    iterations : int
        Sweeps performed (``"nsgs"``) or Lemke's pivots (``"lemke"``).
    error : float
        The natural-map residual divided by ``max(||q||, ||r||, ||u||)`` (see the module
        documentation).
    error_q : float
        The same residual divided by ``||q||``: half of the verdict.
    error_q_floor : float
        The rounding level of ``error_q`` at this answer (see the module documentation).
    scaled_error : float
        The unit-consistent measure, the other half of the verdict (see the module
        documentation).
    min_normal_impulse, max_complementarity, cone_violation, dissipation_violation : float
        The separate checks (see the module documentation).
    solve_time : float
        Seconds spent in the Rust core.
    """

    impulse: NDArray[np.float64]
    velocity: NDArray[np.float64]
    success: bool
    status: Status
    message: str
    iterations: int
    error: float
    error_q: float
    error_q_floor: float
    scaled_error: float
    min_normal_impulse: float
    max_complementarity: float
    cone_violation: float
    dissipation_violation: float
    solve_time: float


@accepts("method", (NSGSSettings, PolyhedralSettings, ProxSettings))
def solve(
    W: ArrayLike,
    q: ArrayLike,
    mu: ArrayLike,
    dim: int = 3,
    method: Method = "nsgs",
    *,
    tol: float = 1e-8,
    max_iter: int | None = None,
    relaxation: float = 1.0,
    initial: ArrayLike | None = None,
    facets: int | None = None,
    eta: float | None = None,
    order: str | ArrayLike = "forward",
    sticking: bool = True,
    settings: NSGSSettings | PolyhedralSettings | ProxSettings | None = None,
) -> ContactResult:
    """Solve the friction-contact problem ``u = W r + q`` with Coulomb's law at every contact.

    Parameters
    ----------
    W : (dim nc, dim nc) array_like, or scipy.sparse array or matrix
        The Delassus matrix (symmetric positive semidefinite). Dense input is solved on dense
        storage. A scipy.sparse W (CSR, CSC, COO, BSR, ... ; converted to CSR here if needed,
        its arrays then passed to the core without a copy) is stored block-sparse, as
        ``dim x dim`` tiles, and never densified: an NSGS sweep then costs O(nnz(W)). Both
        storages give bitwise identical answers on the same W.
    q : (dim nc,) array_like
        The free contact velocity, contact by contact, normal first.
    mu : float, (nc,) or (nc, 2) array_like
        The friction coefficient, one for all contacts or one per contact; ``>= 0``. When an
        array, its length fixes nc; when a scalar, ``nc = len(q) // dim``. In 3D an (nc, 2)
        array gives anisotropic friction: per contact the pair ``(mu_1, mu_2)`` along the two
        tangents, the friction set being the ellipse
        ``(P_t1 / mu_1)^2 + (P_t2 / mu_2)^2 <= P_n^2`` (for ``"lemke"`` the polygon's
        directions are scaled onto the ellipse: ``(mu_1 cos a_k, mu_2 sin a_k) / max(mu_1, mu_2)``).
    dim : {2, 3}
        Components per contact.
    method : {"nsgs", "lemke", "prox"}
        See the module documentation (``"prox"`` is the robust mode).
    tol : float
        Tolerance on ``scaled_error`` for ``success`` (every method; for ``"lemke"`` in 3D,
        on Lemke's LCP error measures); in (0, 1).
    max_iter : int, optional
        Sweep limit (at least 1; default 1000) for ``"nsgs"``; pivot limit for ``"lemke"``
        (default Lemke's own, ``max(1000, 50 n)`` for n LCP unknowns).
    relaxation : float
        Relaxation ω in (0, 2); 1 is plain Gauss-Seidel (``"nsgs"`` only).
    initial : (nc, dim) or (dim nc,) array_like, optional
        Warm start impulses (e.g. the previous step's ``impulse``); projected on the cones
        first (``"nsgs"`` only).
    facets : int, optional
        ``"lemke"`` only: tangent directions per frictional contact, in +/- pairs: even and at
        least 4 in 3D (default 8, at most 1024); exactly 2 in 2D (the default, and exact).
    eta : float, optional
        ``"prox"`` only: the initial proximal parameter relative to W's mean diagonal (> 0,
        default 0.1).
    order : {"forward", "backward", "symmetric"} or (nc,) array of int
        ``"nsgs"`` only: the order in which a sweep visits the contacts; ``"symmetric"`` is a
        forward then a backward pass (no directional bias in stacks and chains, twice the cost
        per sweep); an array is a permutation of the contacts.
    sticking : bool
        ``"nsgs"`` only: when the sweeps slow down, and once more on the last iterate when
        ``max_iter`` is spent, also try the exact answer on the contacts' current cases, the
        least-norm impulses that stop the sticking contacts (default True; kept only when it
        passes ``tol`` or halves ``scaled_error``). False gives plain Gauss-Seidel sweeps,
        the method the literature's tables time sweep for sweep.
    settings : NSGSSettings, PolyhedralSettings or ProxSettings, optional
        The method and its options as one object (:mod:`coulomb.settings`), in place of
        ``method`` and ``tol``, ``max_iter``, ``relaxation``, ``order``, ``sticking``,
        ``facets``, ``eta``;
        ``initial`` combines with it. A keyword also given in it raises
        :class:`~coulomb.errors.SettingsConflictError`.

    Returns
    -------
    ContactResult

    Raises
    ------
    ShapeError, NonFiniteError, InvalidParameterError
        Before any work, for bad input (shapes that do not fit, NaN or infinity, ``mu < 0``,
        ``dim`` not 2 or 3, an unknown method, ``tol <= 0``, ``max_iter < 1``, ``relaxation``
        outside (0, 2), ``facets`` odd or too small, or an option the method does not take).
    """
    # type and range of every option, method, relaxation and facets only with their method
    dim, tol, max_iter, relaxation, facets, eta = _validate.contact_options(
        dim, method, tol, max_iter, relaxation, facets, eta)
    if method != "prox" and eta is not None:
        raise InvalidParameterError("eta applies to method='prox' only")
    sticks = _validate.sticking(sticking, method)
    if method == "lemke":
        if initial is not None:
            raise InvalidParameterError(
                "initial (warm start impulses) applies to method='nsgs' only"
            )
        if facets is None:
            facets = 8 if dim == 3 else 2
        # checked here, not left to the core: the core checks facets after rescaling W
        if dim == 2 and facets != 2:
            raise InvalidParameterError(
                f"facets must be 2 in 2D (the tangent directions +1 and -1, which are exact), "
                f"got {facets}"
            )
        if dim == 3 and (facets < 4 or facets % 2 != 0):
            raise InvalidParameterError(
                f"facets must be even and at least 4 in 3D (tangent directions in +/- pairs), "
                f"got {facets}"
            )
    qa = _as_array(q, "q", 1)
    n = qa.shape[0]
    if n % dim != 0:
        raise ShapeError(f"q has length {n}, which is not a multiple of dim = {dim}")
    nc = n // dim
    mua, pairs = _friction(mu, nc, n, dim)
    Wa, csr = _delassus(W, n)
    # W and q are checked for NaN and infinity by the core, before any work
    init = None
    if initial is not None:
        r0 = _as_array(initial, "initial", None)
        if r0.shape not in ((nc, dim), (n,)):
            got = "a scalar" if np.ndim(initial) == 0 else f"shape {r0.shape}"
            raise ShapeError(f"initial must have shape ({nc}, {dim}) or ({n},), got {got}")
        init = np.ascontiguousarray(r0.reshape(n))
        if not np.isfinite(init).all():
            raise NonFiniteError("initial contains NaN or infinity")
    order_name, permutation = _order(order, nc, method)
    # the core fills a ContactResult itself (its status a Status member)
    return _core.contact_solve(
        Wa,
        qa,
        mua,
        dim,
        method,
        float(tol),
        None if max_iter is None else int(max_iter),
        float(relaxation),
        init,
        facets,
        w_csr=csr,
        mu_pair=pairs,
        eta=None if eta is None else float(eta),
        order=order_name,
        permutation=permutation,
        sticking=sticks,
    )


def _order(order: object, nc: int, method: str) -> tuple[str, list[int] | None]:
    """The NSGS sweep order as the core takes it: a name, or "custom" and a permutation."""
    if isinstance(order, str):
        if order not in ("forward", "backward", "symmetric"):
            raise InvalidParameterError(
                f"order must be 'forward', 'backward', 'symmetric' or a permutation of the "
                f"{nc} contacts, got {order!r}"
            )
        if order != "forward" and method != "nsgs":
            raise InvalidParameterError("order applies to method='nsgs' only")
        return order, None
    if method != "nsgs":
        raise InvalidParameterError("order applies to method='nsgs' only")
    perm = np.asarray(order)
    if perm.ndim != 1 or not np.issubdtype(perm.dtype, np.integer):
        raise InvalidParameterError("a custom order must be a 1-D array of contact indices")
    if perm.shape[0] != nc or sorted(perm.tolist()) != list(range(nc)):
        raise InvalidParameterError(f"a custom order must be a permutation of 0..{nc - 1}")
    return "custom", [int(i) for i in perm]


def _is_scipy_sparse(W: object) -> bool:
    """A scipy.sparse array or matrix, recognised without importing scipy."""
    return type(W).__module__.startswith("scipy.sparse") and callable(getattr(W, "tocsr", None))


def _delassus(
    W: object, n: int
) -> tuple[NDArray[np.float64] | None, tuple[int, NDArray[Any], NDArray[Any], NDArray[Any]] | None]:
    """W as a dense float64 array, or (for scipy.sparse input) as the CSR arrays
    ``(n, indptr, indices, data)`` the core reads without a copy and stores block-sparse."""
    if not _is_scipy_sparse(W):
        Wa = _as_array(W, "W", 2)  # type: ignore[arg-type]
        if Wa.shape != (n, n):
            raise ShapeError(
                f"W must have shape ({n}, {n}) to match q of length {n}, got {Wa.shape}"
            )
        return Wa, None
    shape = tuple(W.shape)  # type: ignore[attr-defined]
    if shape != (n, n):
        raise ShapeError(f"W must have shape ({n}, {n}) to match q of length {n}, got {shape}")
    _validate.sparse_structure("W", W)  # before scipy's conversion trusts the indices
    csr = W.tocsr()  # type: ignore[attr-defined]  # no copy when already CSR
    data = csr.data
    if np.iscomplexobj(data):
        raise InvalidInputError("W must be real, got a complex sparse matrix")
    if data.dtype != np.float64 or not data.flags.c_contiguous:
        data = np.ascontiguousarray(data, dtype=np.float64)
    indptr, indices = csr.indptr, csr.indices
    if not (indptr.dtype == indices.dtype and indptr.dtype in (np.int32, np.int64)):
        indptr = np.ascontiguousarray(indptr, dtype=np.int64)
        indices = np.ascontiguousarray(indices, dtype=np.int64)
    # W's data is checked for NaN and infinity, and its indices for range, by the core
    return None, (n, indptr, indices, data)


def _friction(
    mu: ArrayLike, nc: int, n: int, dim: int
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
    """mu as ``nc`` coefficients, and for an (nc, 2) array the flat anisotropic pairs (the
    coefficients then hold ``max(mu_1, mu_2)``)."""
    if type(mu) is float:
        # one coefficient as a Python number: checked here (the numpy route below costs
        # about 4 us, more than a small solve)
        if not math.isfinite(mu):
            raise NonFiniteError("mu contains NaN or infinity")
        if mu < 0:
            raise InvalidParameterError(f"friction coefficients must be >= 0, mu[0] = {mu}")
        mua = np.empty(nc)
        mua.fill(mu)
        return mua, None
    mu_in = np.asarray(mu) if not isinstance(mu, np.ndarray) else mu
    pairs = None
    if mu_in.ndim == 0:
        mua = np.full(nc, float(_as_array(np.atleast_1d(mu_in), "mu", 1)[0]))
    elif mu_in.ndim == 2:
        m2 = _as_array(mu_in, "mu", 2)
        if m2.shape != (nc, 2):
            raise ShapeError(
                f"anisotropic mu must have shape ({nc}, 2) (one pair mu_1, mu_2 per contact; "
                f"q of length {n} holds nc = {nc} contacts), got {m2.shape}"
            )
        if dim != 3:
            raise InvalidParameterError(
                "anisotropic friction (mu of shape (nc, 2)) needs dim = 3 (two tangents)"
            )
        if not np.isfinite(m2).all():
            raise NonFiniteError("mu contains NaN or infinity")
        if (m2 < 0).any():
            k, j = (int(v) for v in np.argwhere(m2 < 0)[0])
            raise InvalidParameterError(
                f"friction coefficients must be >= 0, mu[{k}, {j}] = {m2[k, j]}"
            )
        pairs = np.ascontiguousarray(m2.reshape(2 * nc))
        mua = np.ascontiguousarray(m2.max(axis=1)) if nc else np.zeros(0)
    else:
        mua = _as_array(mu_in, "mu", 1)
        if mua.shape[0] != nc:
            raise ShapeError(
                f"mu has {mua.shape[0]} entries but q of length {n} holds nc = {n} / {dim} = "
                f"{nc} contacts"
            )
    if not np.isfinite(mua).all():
        raise NonFiniteError("mu contains NaN or infinity")
    if (mua < 0).any():
        k = int(np.flatnonzero(mua < 0)[0])
        raise InvalidParameterError(f"friction coefficients must be >= 0, mu[{k}] = {mua[k]}")
    return mua, pairs


# the batch (its own file); imported last, as it reads the names above
from ._contact_batch import ContactBatchResult, solve_batch  # noqa: E402
