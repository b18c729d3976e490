"""A result object in the manner of ``scipy.optimize.OptimizeResult``."""

from __future__ import annotations

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


class Result(dict):
    """A dict whose keys are also attributes, with a readable ``repr``.

    Every result has ``success`` (the answer passed the tolerance on the original data),
    ``status`` (a short string) and ``message`` (one line for a person).
    """

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
