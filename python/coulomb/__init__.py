"""coulomb: rigid-body dynamics with Coulomb friction and impact.

Exact where peers approximate, and fast: the solvers run in Rust, every answer comes with its
error measured on the original data.

Submodules
----------
lcp
    Linear complementarity problems (Lemke, projected Gauss-Seidel, enumeration).
contact
    Frictional contact over a frozen Delassus matrix: nonsmooth Gauss-Seidel on the exact cone,
    the polyhedral-cone LCP by Lemke, the robust mode (``method="prox"``), and the assembly of
    W = G^T M^-1 G.
model
    Scenes (bodies, contact shapes, half-spaces, pairs) and ``Scene.simulate``: Stewart's
    impulse time stepper (Stewart 2000; Stewart and Trinkle 1996), run in Rust.
    :func:`coulomb.rollout` simulates many scenes at once across the cores (as
    ``lcp.solve_batch`` and ``contact.solve_batch`` solve many problems).
trajectory
    The simulation result with its per-step checks (``Trajectory.check``) and plots.
joints
    Joints (revolute, prismatic, spherical, fixed) between bodies or a body and the world,
    with limits and restitution, added to a scene with ``Scene.add``.
io
    Readers for benchmark problem files (Siconos LCP and friction contact, FCLib HDF5).
painleve
    Painleve's sliding rod: A(theta), b and which smooth contact modes exist.
regularized
    The tanh-smoothed friction law on a ramp (stiff ODE), to compare with exact Coulomb friction.
extremes
    The stability suite at the extremes (mass ratios, friction, restitution, steps, units).
settings
    Settings objects (``NSGSSettings``, ``LemkeSettings``, ``StepSettings``, ...) that the
    solvers and the stepper take as ``settings=`` in place of their keywords.
study
    Sweeps of the settings a user trades (error against cost, Pareto fronts, orders).
errors
    The exceptions raised for bad input.
validate
    Reproduces the reference figures of the chapter (``coulomb validate``).

The physics follows D. E. Stewart, "Rigid-Body Dynamics with Friction and Impact", SIAM Review
42(1), 2000, as taught in Satici, *Kinematics and Machine Dynamics*, ch. 11 ("the chapter" in
these docs: its worked examples are the scalar LCPs, the inelastic contact step, Painleve's rod,
the ramp and the floor impact).
"""

from __future__ import annotations

from . import (
    contact,
    errors,
    extremes,
    io,
    joints,
    lcp,
    model,
    painleve,
    regularized,
    settings,
    study,
    trajectory,
)
from ._core import __version__, memory_budget, set_memory_budget
from ._result import Result
from ._rollout import rollout
from ._status import Status
from .contact import ContactResult
from .joints import Fixed, Prismatic, Revolute, Spherical, Weld
from .lcp import LcpResult
from .model import (
    Box,
    Capsule,
    Compound,
    Cone,
    ConvexHull,
    Cylinder,
    Disk,
    GapContact,
    HalfSpace,
    Heightfield,
    Model,
    Particle,
    Point,
    Polygon,
    Polyline,
    RigidBody2D,
    RigidBody3D,
    Scene,
    Segment,
    Sphere,
    TriangleMesh,
)
from .settings import (
    LemkeSettings,
    NSGSSettings,
    PGSSettings,
    PolyhedralSettings,
    ProxSettings,
    StepSettings,
)
from .trajectory import Trajectory

__all__ = [
    "Box",
    "Capsule",
    "Compound",
    "Cone",
    "ContactResult",
    "ConvexHull",
    "Cylinder",
    "Disk",
    "Fixed",
    "GapContact",
    "HalfSpace",
    "Heightfield",
    "LcpResult",
    "LemkeSettings",
    "Model",
    "NSGSSettings",
    "PGSSettings",
    "Particle",
    "Point",
    "Polygon",
    "PolyhedralSettings",
    "Polyline",
    "Prismatic",
    "ProxSettings",
    "Result",
    "Revolute",
    "RigidBody2D",
    "RigidBody3D",
    "Scene",
    "Segment",
    "Sphere",
    "Spherical",
    "Status",
    "StepSettings",
    "Trajectory",
    "TriangleMesh",
    "Weld",
    "__version__",
    "contact",
    "errors",
    "extremes",
    "io",
    "joints",
    "lcp",
    "memory_budget",
    "model",
    "painleve",
    "regularized",
    "rollout",
    "set_memory_budget",
    "settings",
    "study",
    "trajectory",
]
