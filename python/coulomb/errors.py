"""Exceptions raised by coulomb.

Bad input is refused before any work with one of the :class:`InvalidInputError` subclasses
(each is also a :class:`ValueError`). A solver that runs but does not converge does *not*
raise: its result's ``status`` says what happened and ``success`` is False.
"""

from __future__ import annotations

__all__ = [
    "ArgumentTypeError",
    "CoulombError",
    "InternalError",
    "InvalidInputError",
    "InvalidParameterError",
    "NonFiniteError",
    "ProblemFormatError",
    "ProblemTooLargeError",
    "SettingsConflictError",
    "ShapeError",
]


class CoulombError(Exception):
    """Base class of every exception coulomb raises on purpose."""


class InvalidInputError(CoulombError, ValueError):
    """The input cannot be solved as given (checked before any work)."""


class ShapeError(InvalidInputError):
    """Arrays of the wrong dimension or of shapes that do not fit together."""


class NonFiniteError(InvalidInputError):
    """A NaN or an infinity in the data."""


class InvalidParameterError(InvalidInputError):
    """An option outside its domain (for example ``tol <= 0`` or an unknown method)."""


class SettingsConflictError(InvalidParameterError):
    """A settings object (:mod:`coulomb.settings`) given together with a keyword for one of its
    fields, or with a method it does not stand for: each setting must be given once."""


class ArgumentTypeError(InvalidParameterError, TypeError):
    """An argument of the wrong type (a float or a string where an int count is expected,
    None where a number is): both an :class:`InvalidParameterError` and a ``TypeError``."""


class ProblemTooLargeError(InvalidInputError):
    """The problem is too large for the chosen method or the memory budget (enumeration
    beyond n = 15, a dense LCP or a trajectory whose bytes exceed
    ``coulomb.memory_budget()``)."""


class ProblemFormatError(CoulombError, ValueError):
    """A problem file that does not follow its format."""


class InternalError(CoulombError, RuntimeError):
    """A bug in coulomb (a Rust panic caught at the boundary). Please report it."""
