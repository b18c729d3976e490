"""What the batches share (:func:`coulomb.lcp.solve_batch`, :func:`coulomb.contact.solve_batch`):
the input as one stacked array or a list of arrays, the ``threads`` keyword, and
:class:`BatchResult`, the sequence of per-problem results made on demand from the columns the
core returns."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, Generic, TypeVar, overload

import numpy as np
from numpy.typing import NDArray

from . import _validate
from ._result import Result
from ._status import Status
from .errors import ArgumentTypeError, CoulombError, ShapeError

#: the most threads a batch may ask for (Rust ``batch::MAX_THREADS``).
MAX_THREADS = 1024

R = TypeVar("R", bound=Result)


def threads_option(threads: Any) -> int | None:
    """None (all the cores) or a thread count in [1, 1024]."""
    return None if threads is None else _validate.count("threads", threads, maximum=MAX_THREADS)


def at_problem(i: int, fn: Callable[..., Any], *args: Any, what: str = "problem") -> Any:
    """``fn(*args)``, a :class:`~coulomb.errors.CoulombError` it raises re-raised (same class)
    with the problem's (or scene's, ``what``) index in front of its message."""
    try:
        return fn(*args)
    except CoulombError as exc:
        raise type(exc)(f"{what} {i}: {exc}") from None


def stacked(
    xs: Any, name: str, ndim: int
) -> NDArray[np.float64] | list[NDArray[np.float64]]:
    """The problems' arrays of ``ndim`` dimensions each: an ndarray of ``ndim + 1`` dimensions
    is one stack (float64, C-contiguous, no copy when it already is one); anything else is a
    sequence of arrays, each checked and named ``name[i]``."""
    if isinstance(xs, np.ndarray) and xs.ndim == ndim + 1:
        return _validate.array(xs, name, ndim + 1)
    if isinstance(xs, (str, bytes, np.ndarray)) or not isinstance(xs, Sequence):
        shape = f" of shape {xs.shape}" if isinstance(xs, np.ndarray) else ""
        raise ArgumentTypeError(
            f"{name} must be a {ndim + 1}-D array or a sequence of {ndim}-D arrays, got "
            f"{type(xs).__name__}{shape}")
    return [_validate.array(x, f"{name}[{i}]", ndim) for i, x in enumerate(xs)]


def count_of(xs: NDArray[np.float64] | list[NDArray[np.float64]]) -> int:
    return xs.shape[0] if isinstance(xs, np.ndarray) else len(xs)


def rows(xs: NDArray[np.float64] | list[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
    return list(xs)


def per_problem(value: Any, name: str, count: int) -> list[Any]:
    """An option given per problem: a sequence (or array) with one entry per problem."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        raise ArgumentTypeError(
            f"{name} must give one entry per problem (a sequence of {count}), got "
            f"{type(value).__name__}")
    if len(value) != count:
        raise ShapeError(f"{name} must give one entry per problem ({count}), got {len(value)}")
    return list(value)


#: the message length the core records for a message kept whole in the overflow.
_OVERFLOWED = 0xFFFF


class BatchResult(Sequence[R], Generic[R]):
    """The answers of a batch: a sequence with one result per problem, in order (``len``,
    indexing, slicing and iteration; each item is the result object the one-at-a-time solve
    returns, equal to it entry by entry), and every scalar field as one array over the batch
    (``success``, ``status``, ``error``, ``iterations``, ...).

    Attributes
    ----------
    success : ndarray of bool
        Per problem, whether its answer passed the tolerance.
    status : ndarray of Status
        Per problem, how its solve ended.
    message : list of str
        Per problem, one line for a person.
    solve_time : ndarray
        Per problem, seconds its solve took in the Rust core.
    wall_time : float
        Seconds the whole call took (checks, the solves on every thread, the columns).
    """

    #: the status names, in the order of the core's status codes.
    _STATUS: tuple[str, ...] = ()
    #: the per-problem vector fields (flat in the columns, cut by ``offsets``).
    _VECTORS: tuple[str, ...] = ()
    #: the per-problem scalar fields, each an array over the batch.
    _SCALARS: tuple[str, ...] = ()
    _ITEM: type[Result] = Result

    def __init__(self, columns: Mapping[str, Any], wall_time: float,
                 shape: tuple[int, ...] | None = None) -> None:
        #: every problem's vector shape when the input was one stack (known when empty too)
        self._shape = shape
        self._cols = columns
        offsets = np.asarray(columns["offsets"])
        self._offsets = offsets
        self._count = len(offsets) - 1
        self._codes = np.asarray(columns["status"])
        self.success = self._codes == 0
        # each message in a slot of bytes filled in place by the core (a longer one whole in
        # the overflow): no text is joined or decoded until it is read
        self._message_slot = int(columns["message_slot"])
        self._message_bytes = np.asarray(columns["message_bytes"])
        self._message_lengths = np.asarray(columns["message_lengths"])
        self._message_overflow: Mapping[int, str] = columns["message_overflow"]
        self.wall_time = float(wall_time)

    @property
    def status(self) -> NDArray[np.object_]:
        """Per problem, how its solve ended (a :class:`Status`; made when first read)."""
        made = self.__dict__.get("_status")
        if made is None:
            kinds = np.array([Status(s) for s in self._STATUS] or [Status.SOLVED], dtype=object)
            made = kinds[self._codes] if self._count else np.empty(0, dtype=object)
            self._status = made
        return made

    @property
    def message(self) -> list[str]:
        """Per problem, one line for a person."""
        return [self._message(i) for i in range(self._count)]

    def _message(self, i: int) -> str:
        n = int(self._message_lengths[i])
        if n == _OVERFLOWED:
            return self._message_overflow[i]
        a = i * self._message_slot
        return self._message_bytes[a:a + n].tobytes().decode()

    def __len__(self) -> int:
        return self._count

    @overload
    def __getitem__(self, index: int) -> R: ...

    @overload
    def __getitem__(self, index: slice) -> list[R]: ...

    def __getitem__(self, index: int | slice) -> R | list[R]:
        if isinstance(index, slice):
            return [self._item(i) for i in range(*index.indices(self._count))]
        i = int(index)
        if i < 0:
            i += self._count
        if not 0 <= i < self._count:
            raise IndexError(f"problem {index} of a batch of {self._count}")
        return self._item(i)

    def __iter__(self) -> Iterator[R]:
        for i in range(self._count):
            yield self._item(i)

    def __getattr__(self, name: str) -> Any:
        # the scalar fields as arrays over the batch (the vectors through `vectors`)
        cols = self.__dict__.get("_cols")
        if cols is not None and name in self._VECTORS:
            return self.vectors(name)
        if cols is not None and name in self._SCALARS:
            return np.asarray(cols[name])
        raise AttributeError(name)

    def vectors(self, name: str) -> NDArray[np.float64] | list[NDArray[np.float64]]:
        """Field ``name`` of every problem: one array of shape ``(B, *shape)`` when every
        problem has the same size (a view of the batch's memory), else a list of arrays."""
        flat = np.asarray(self._cols[name])
        sizes = np.diff(self._offsets)
        if self._shape is not None:
            return flat.reshape((self._count, *self._shape))
        if self._count and (sizes == sizes[0]).all():
            return flat.reshape((self._count, *self._item_shape(0)))
        return [flat[a:b].reshape(self._item_shape(i))
                for i, (a, b) in enumerate(zip(self._offsets[:-1], self._offsets[1:], strict=True))]

    def _item_shape(self, i: int) -> tuple[int, ...]:
        return (int(self._offsets[i + 1] - self._offsets[i]),)

    def _vector(self, name: str, i: int) -> NDArray[np.float64]:
        a, b = int(self._offsets[i]), int(self._offsets[i + 1])
        return np.array(self._cols[name][a:b]).reshape(self._item_shape(i))

    def _item(self, i: int) -> R:
        raise NotImplementedError

    def __repr__(self) -> str:
        solved = int(self.success.sum())
        return (f"{type(self).__name__}({self._count} problems, {solved} solved, "
                f"wall_time={self.wall_time:.3g} s)")
