"""The ``coulomb`` command line."""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict
from pathlib import Path

from . import __version__
from ._extras import MissingExtraError, require
from ._readable import readable
from .errors import CoulombError


def _validate(args: argparse.Namespace) -> int:
    from .validate import format_table, run

    rows = run(args.data, progress=lambda m: print(m, file=sys.stderr))
    if args.json:
        print(json.dumps([asdict(r) for r in rows], indent=2))
    else:
        print(format_table(rows))
    return 0 if all(r.passed for r in rows) else 1


def _solve_lcp(args: argparse.Namespace) -> int:
    from . import lcp
    from .io import read_siconos_lcp

    p = read_siconos_lcp(args.path)
    r = lcp.solve(p.M, p.q, method=args.method, tol=args.tol)
    print(f"{p.name}: n = {p.n}")
    print(r)
    return 0 if r.success else 2


def _study(args: argparse.Namespace) -> int:
    from . import study

    if args.list:
        for name, p in study.PRESETS.items():
            print(f"{name:18s} {p['about']}")
        return 0
    if args.name is None:
        print("coulomb study: give a study name (see --list)", file=sys.stderr)
        return 2
    if args.name not in study.PRESETS:
        print(
            f"coulomb study: unknown study {args.name!r} (see --list: {', '.join(study.PRESETS)})",
            file=sys.stderr,
        )
        return 2
    # optional dependencies first: say what is missing before any work
    study.require_preset(args.name)
    if args.plot:
        require("matplotlib", extra="plot", what="coulomb study --plot")
    executor = None
    if args.processes > 1:
        from concurrent.futures import ProcessPoolExecutor

        executor = ProcessPoolExecutor(max_workers=args.processes)
    try:
        s = study.run_preset(args.name, executor=executor, progress=not args.quiet)
    finally:
        if executor is not None:
            executor.shutdown()
    preset = study.PRESETS[args.name]
    print(s)
    worst = max(r["error"] for r in s.records)
    if worst <= 1e-12:
        print(f"the error is at most {readable(worst)} at every point: exact, no order to measure")
    else:
        order = s.order(preset["order"], where=preset.get("order_where"))
        print(f"measured order of the error in {preset['order']}: {order:.3f}")
    if args.csv:
        print(f"wrote {s.to_csv(args.csv)}")
    if args.json:
        s.to_json(args.json)
        print(f"wrote {args.json}")
    if args.plot:
        s.plot(path=args.plot)
        print(f"wrote {args.plot}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``coulomb`` console script."""
    parser = argparse.ArgumentParser(
        prog="coulomb",
        description="Rigid-body dynamics with Coulomb friction and impact.",
    )
    parser.add_argument("--version", action="version", version=f"coulomb {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    v = sub.add_parser(
        "validate", help="reproduce the worked figures of Stewart (2000) and print them"
    )
    v.add_argument("--data", type=Path, default=None, help="benchmark data folder")
    v.add_argument("--json", action="store_true", help="print the rows as JSON")
    v.set_defaults(func=_validate)

    s = sub.add_parser("solve-lcp", help="solve a Siconos LCP file and print the result")
    s.add_argument("path", type=Path)
    s.add_argument("--method", default="lemke", choices=["lemke", "pgs", "enumerate"])
    s.add_argument("--tol", type=float, default=1e-9)
    s.set_defaults(func=_solve_lcp)

    st = sub.add_parser("study", help="measure the speed-accuracy trade of a named study")
    st.add_argument("name", nargs="?", help="the study (see --list)")
    st.add_argument("--list", action="store_true", help="list the named studies")
    st.add_argument("--processes", type=int, default=1, help="run the points in N processes")
    st.add_argument("--csv", type=Path, default=None, help="write the records as CSV")
    st.add_argument("--json", type=Path, default=None, help="write the records as JSON")
    st.add_argument("--plot", type=Path, default=None, help="write error against time (PNG)")
    st.add_argument("--quiet", action="store_true", help="no progress lines")
    st.set_defaults(func=_study)

    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (OSError, CoulombError, MissingExtraError) as exc:
        print(f"coulomb {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
