#!/usr/bin/env python3
"""The robust mode (``method="prox"``) on every problem ``benches/peer_contact.py`` reads (the
FCLib subset and the Siconos friction-contact files, the slow ones included), one solve each
at tol 1e-8 and at most 200 Newton steps, zero start, dense W; success is the recomputed
``error_q <= tol`` of ``peer_contact.error_q``. The figures of BENCHMARKS.md, "The robust
mode". Times are wall-clock of one solve on a shared machine: indicative only.

Example::

    COULOMB_DATA=../shared/data python benches/prox_survey.py
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import peer_contact as pc


def main() -> None:
    ok: dict[str, list[int]] = {}
    for p in pc.load_problems(None, include_slow=True):
        r = pc.run_coulomb(p, "prox", 1e-8, 200)
        tally = ok.setdefault(p.source, [0, 0])
        tally[0] += r.success
        tally[1] += 1
        verdict = "ok" if r.success else f"FAIL {r.note or 'solved, error_q above tol'}"
        print(f"{p.source:10s} {p.name:50s} dim {p.dim} nc {p.nc:5d} steps {r.iterations:4d} "
              f"error_q {r.error_q:.1e} {r.seconds * 1e3:9.1f} ms {verdict}", flush=True)
    for source, (good, total) in ok.items():
        print(f"{source}: {good} of {total} with error_q <= 1e-8")


if __name__ == "__main__":
    main()
