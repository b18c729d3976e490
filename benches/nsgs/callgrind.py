"""Instructions per contact per NSGS sweep, by callgrind.

    python benches/nsgs/callgrind.py [--exe PATH] [--sweeps N] [--raw RAW_DIR]

Runs ``target/release/examples/nsgs_sweeps`` (benches/nsgs/sweeps.rs; built first unless
``--exe`` names a binary) under ``valgrind --tool=callgrind`` on the block-sparse pile of
``cargo bench --bench contact`` (nc = 1000) and a few FCLib / Siconos problems, each a solve of
exactly N sweeps from zero, and reads with ``callgrind_annotate --inclusive=yes`` the inclusive
count of the sweep function (``Sweep::visit``): divided by the sweeps and nc, the instructions
per contact per sweep, independent of the machine's load. RAW_DIR holds the FCLib problems
written by ``benches/nsgs/dump_fclib.py`` (default ``target/fclib-raw``; problems not found
there are skipped). Prints one line per problem.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXE = ROOT / "target" / "release" / "examples" / "nsgs_sweeps"
DATA = Path(os.environ.get("COULOMB_DATA", ROOT.parent / "shared" / "data"))

#: (name, nc, argument after SWEEPS: "pile NC", a raw FCLib file or a Siconos .dat file)
PROBLEMS: list[tuple[str, list[str]]] = [
    ("pile nc = 1000", ["pile", "1000"]),
    ("OneObject-i100000-316", ["siconos:OneObject-i100000-316.hdf5.dat"]),
    ("Capsules-i101-404", ["siconos:Capsules-i101-404.dat"]),
    ("RockPile_tob1", ["siconos:RockPile_tob1.dat"]),
    ("KaplasTower-i1061-4", ["raw:KaplasTower-i1061-4.fc"]),
    ("LMGC_100_PR_PerioBox-i00361-60-03000", ["raw:LMGC_100_PR_PerioBox-i00361-60-03000.fc"]),
]

SWEEP = re.compile(r"Sweep.*::visit")


def resolve(argv: list[str], raw: Path) -> list[str] | None:
    a = argv[0]
    if a.startswith("siconos:"):
        f = DATA / "siconos-fc" / a.split(":", 1)[1]
    elif a.startswith("raw:"):
        f = raw / a.split(":", 1)[1]
    else:
        return argv
    return [str(f)] if f.exists() else None


def count(exe: Path, sweeps: int, argv: list[str]) -> tuple[int, int, str]:
    """(program total, the sweep function's inclusive count, the program's output)."""
    with tempfile.TemporaryDirectory(dir=ROOT / "target") as tmp:
        out = Path(tmp) / "callgrind.out"
        run = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                              str(exe), str(sweeps), *argv], cwd=ROOT, check=True,
                             capture_output=True, text=True)
        text = subprocess.run(["callgrind_annotate", "--inclusive=yes", str(out)], check=True,
                              capture_output=True, text=True).stdout
    total = 0
    sweep = 0
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+)\s", line)
        if not m:
            continue
        n = int(m.group(1).replace(",", ""))
        if "PROGRAM TOTALS" in line:
            total = n
        elif SWEEP.search(line):
            sweep += n
    return total, sweep, run.stdout.strip()


def nc_of(output: str, argv: list[str]) -> int:
    m = re.search(r"nc (\d+)", output)
    return int(m.group(1)) if m else 0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--exe", type=Path, help="the nsgs_sweeps binary (default: build it)")
    ap.add_argument("--sweeps", type=int, default=20)
    ap.add_argument("--raw", type=Path, default=ROOT / "target" / "fclib-raw")
    ap.add_argument("names", nargs="*", help="only problems whose name contains one of these")
    args = ap.parse_args()
    exe = args.exe or EXE
    if args.exe is None:
        subprocess.run(["cargo", "build", "--release", "--example", "nsgs_sweeps"], cwd=ROOT,
                       check=True)
    for name, argv in PROBLEMS:
        if args.names and not any(n in name for n in args.names):
            continue
        real = resolve(argv, args.raw)
        if real is None:
            print(f"{name}: not found, skipped")
            continue
        total, sweep, output = count(exe, args.sweeps, real)
        nc = nc_of(output, real)
        per = sweep / args.sweeps / nc if nc else float("nan")
        print(f"{name}: nc {nc}, {args.sweeps} sweeps: sweep function {sweep:,} instructions "
              f"({per:,.0f} per contact per sweep), program {total:,}  [{output}]")


if __name__ == "__main__":
    main()
