"""Identity lookups for a scene's lists (:class:`coulomb.model.Scene`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from .errors import InvalidParameterError


class _Registry:
    """Where each object of one of a scene's lists is, by identity, in O(1): a scene of 10^5
    spheres declares 10^5 contacts, and a linear search per declaration made building it
    quadratic. A position found is checked against the list itself, so a hit is always the
    list's own answer; a miss is looked up again in the whole list before it is reported, since
    the list may have been changed behind the scene's back."""

    def __init__(self, what: str, shapes: bool = False) -> None:
        self.what = what
        # the scene's shapes are (body, shape) entries, looked up by their shape
        self.part = 1 if shapes else None
        self.at: dict[int, int] = {}

    def _of(self, item: Any) -> Any:
        return item if self.part is None else item[self.part]

    def appended(self, items: Sequence[Any]) -> None:
        """records the list's last item (the scene just appended it)."""
        self.at[id(self._of(items[-1]))] = len(items) - 1

    def _hit(self, items: Sequence[Any], obj: Any) -> int | None:
        i = self.at.get(id(obj))
        return i if i is not None and i < len(items) and self._of(items[i]) is obj else None

    def holds(self, items: Sequence[Any], obj: Any) -> bool:
        """whether ``obj`` is in the list, as far as the scene appended it: O(1), for the
        checks of a new item, which are misses."""
        return self._hit(items, obj) is not None

    def index(self, items: Sequence[Any], obj: Any) -> int:
        i = self._hit(items, obj)
        if i is None:
            self.at = {id(self._of(x)): j for j, x in enumerate(items)}
            i = self._hit(items, obj)
        if i is None:
            raise InvalidParameterError(f"this {self.what} was not added to the scene")
        return i
