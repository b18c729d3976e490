"""The optional dependencies: which extra of ``pip install 'coulomb[EXTRA]'`` brings each, and
a check that says so before any work is done.

======== ======================== =====================================================
extra    installs                 needed by
======== ======================== =====================================================
hdf5     h5py, scipy              ``coulomb.io.read_fclib`` (FCLib HDF5 files),
                                  ``Scene.stream``, ``Trajectory.load``
plot     matplotlib               ``Trajectory.plot``, ``Trajectory.animate``, ``Study.plot``,
                                  ``coulomb study --plot``
ode      scipy                    ``coulomb.regularized.simulate_ramp``, the
                                  ``regularized-ramp`` study; scipy.sparse input to
                                  ``coulomb.contact``
dask     dask[distributed]        running studies on a Dask cluster (an executor)
all      every one of the above
test     pytest, hypothesis, ...  the test suite
======== ======================== =====================================================
"""

from __future__ import annotations

import importlib

#: extra -> the modules it provides (the table above).
EXTRAS: dict[str, tuple[str, ...]] = {
    "hdf5": ("h5py", "scipy"),
    "plot": ("matplotlib",),
    "ode": ("scipy",),
    "dask": ("dask", "distributed"),
}


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message names the extra that brings it."""

    def __init__(self, module: str, extra: str, what: str) -> None:
        package = module.split(".")[0]
        super().__init__(
            f"{what} needs {package}, which is not installed: "
            f"pip install 'coulomb[{extra}]' (or pip install {package})",
            name=module,
        )
        self.module = module
        self.extra = extra


def require(module: str, *, extra: str, what: str) -> None:
    """Imports ``module`` or raises :class:`MissingExtraError` naming ``extra`` and ``what``
    needs it. Call it first thing, before any work."""
    if extra not in EXTRAS or module.split(".")[0] not in EXTRAS[extra]:
        raise ValueError(f"{module!r} is not a module of the extra {extra!r}")
    try:
        importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(module, extra, what) from exc
