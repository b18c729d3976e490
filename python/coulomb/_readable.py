"""Numbers in messages, printed as the Rust core prints them (``crate::readable``): two
significant digits in scientific notation, a trailing ``.0`` dropped, ``0`` for zero
(``readable(0.0) == "0"``, ``readable(1.23e-15) == "1.2e-15"``, ``readable(1e-9) == "1e-9"``)."""

from __future__ import annotations

import math


def readable(x: float) -> str:
    """``x`` for a message: ``0``, ``1.2e-15``, ``1e-9``, ``-2.5e3``; ``inf``, ``-inf``,
    ``NaN`` as the core prints them."""
    x = float(x)
    if x == 0.0:
        return "0"
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    mantissa, exponent = f"{x:.1e}".split("e")
    return f"{mantissa.removesuffix('.0')}e{int(exponent)}"
