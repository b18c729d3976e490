"""A result object in the manner of ``scipy.optimize.OptimizeResult``."""

from __future__ import annotations

import inspect
from typing import Any

import numpy as np


def _short(value: Any) -> str:
    if isinstance(value, np.ndarray):
        with np.printoptions(threshold=8, edgeitems=3, precision=6, linewidth=88):
            text = np.array2string(value, separator=", ")
        return text.replace("\n", "\n" + " " * 22)
    if isinstance(value, float):
        return f"{value:.6g}"
    return repr(value)


def _item_property(name: str) -> property:
    """A read-only property returning item ``name`` (AttributeError when it is absent)."""

    def get(self: dict[str, Any]) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    return property(get, doc=f"The ``{name!r}`` item.")


class Result(dict):
    """A dict whose keys are also attributes, with a readable ``repr``.

    Every result has ``success`` (the answer passed the tolerance on the original data),
    ``status`` (a short string) and ``message`` (one line for a person).
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        # Each annotated field of a subclass reads its item through a property: found by the
        # type lookup, so `result.z` costs a call instead of a failed lookup, an exception
        # and `__getattr__` (about 0.45 µs per access, several µs per small solve).
        super().__init_subclass__(**kwargs)
        for name in inspect.get_annotations(cls):
            if name not in cls.__dict__:
                setattr(cls, name, _item_property(name))

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError as exc:
            raise AttributeError(name) from exc

    def __setattr__(self, name: str, value: Any) -> None:
        self[name] = value

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self.keys()))

    def __repr__(self) -> str:
        if not self:
            return f"{type(self).__name__}()"
        width = max(map(len, self.keys())) + 1
        lines = [f"{k.rjust(width)}: {_short(v)}" for k, v in self.items()]
        return f"{type(self).__name__}(\n" + "\n".join(lines) + "\n)"

    __str__ = __repr__
