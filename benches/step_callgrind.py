"""The stepper's instruction counts by callgrind, written into BENCHMARKS.md.

    python benches/step_callgrind.py [--no-write] [--label LABEL] [--keep N]

Builds ``target/release/examples/step_profile`` (benches/profile/step_profile.rs), runs it under
``valgrind --tool=callgrind`` on the stepper's benchmark scenes (the box down the ramp, the box
resting on the floor, the ball's floor impact, the pile of 100 spheres, the tower of 10 boxes, the
pile of 216 boxes dropped into a bin, the chain of 20 hinged links) and reads, with
``callgrind_annotate --inclusive=yes``, the program's total and the contact measure's inclusive
count (``contact::measures::measure_into``, every step's verdict). Instruction counts do not
depend on the machine's load, so they compare revisions where wall times on a shared machine
cannot.

The table between ``<!-- step-callgrind:begin -->`` and ``<!-- step-callgrind:end -->`` gets
one pair of columns (total, measure) for this revision (``--label``, default the short commit
hash, ``+`` when the work tree differs from it); the columns of earlier revisions already in
the table are kept (at most ``--keep`` of them besides the first, the reference before the
stage split), so the table reads as a history. ``--no-write`` prints the table only.
"""

from __future__ import annotations

import argparse
import datetime
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from markers import read_block, write_block

ROOT = Path(__file__).resolve().parents[1]
EXE = ROOT / "target" / "release" / "examples" / "step_profile"
MEASURE = "coulomb::contact::measures::measure_into"

#: (row name, step_profile arguments)
SCENES = [
    ("ramp, 5000 steps", ["ramp", "5000"]),
    ("resting box, 5000 steps", ["resting", "5000"]),
    ("floor impact, 200 steps", ["impact", "200"]),
    ("pile of 100, 300 steps", ["pile", "100", "300"]),
    ("tower of 10 boxes, 2000 steps", ["tower", "10", "2000"]),
    ("pile of 216 boxes, 200 steps", ["box-pile", "216", "200"]),
    ("chain of 20 links, 300 steps", ["chain", "20", "300"]),
]


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True,
                          text=True).stdout.strip()


def revision() -> str:
    """The short commit hash, with ``+`` when tracked files differ from it."""
    rev = _git("rev-parse", "--short", "HEAD")
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    return rev + ("+" if dirty else "")


def build() -> None:
    subprocess.run(["cargo", "build", "--release", "--example", "step_profile"], cwd=ROOT,
                   check=True)


def count(args: list[str]) -> tuple[int, int]:
    """(total instructions, the measure's inclusive instructions) of one run."""
    with tempfile.TemporaryDirectory(dir=ROOT / "target") as tmp:
        out = Path(tmp) / "callgrind.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        str(EXE), *args], cwd=ROOT, check=True, capture_output=True)
        text = subprocess.run(["callgrind_annotate", "--inclusive=yes", str(out)], check=True,
                              capture_output=True, text=True).stdout
    total = measure = None
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+)\s", line)
        if not m:
            continue
        n = int(m.group(1).replace(",", ""))
        if "PROGRAM TOTALS" in line:
            total = n
        elif f"{MEASURE} " in line or line.rstrip().endswith(MEASURE):
            measure = n if measure is None else max(measure, n)
    if total is None:
        raise RuntimeError(f"no total in callgrind's report for {args}")
    return total, measure or 0


def _millions(n: int) -> str:
    """Millions to 0.1M from 10M on, to 0.01M from 1M, thousands below."""
    if n >= 10_000_000:
        return f"{n / 1e6:.1f}M"
    if n >= 1_000_000:
        return f"{n / 1e6:.2f}M"
    return f"{n / 1e3:.1f}k"


def parse_table(block: str) -> tuple[list[str], dict[str, dict[str, tuple[str, str]]]]:
    """The revision labels of an existing table and its cells, ``cells[label][scene]``."""
    lines = [ln for ln in block.splitlines() if ln.startswith("|")]
    if len(lines) < 3:
        return [], {}
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    labels = [h.rsplit(":", 1)[0] for h in head[1::2]]
    cells: dict[str, dict[str, tuple[str, str]]] = {lab: {} for lab in labels}
    for ln in lines[2:]:
        row = [c.strip() for c in ln.strip("|").split("|")]
        for k, lab in enumerate(labels):
            if 2 + 2 * k < len(row):
                cells[lab][row[0]] = (row[1 + 2 * k], row[2 + 2 * k])
    return labels, cells


def table(labels: list[str], cells: dict[str, dict[str, tuple[str, str]]]) -> str:
    head = "| scene | " + " | ".join(f"{lab}: total | {lab}: measure" for lab in labels) + " |"
    rule = "|---|" + "---:|---:|" * len(labels)
    rows = []
    for name, _ in SCENES:
        row = [name]
        for lab in labels:
            row.extend(cells[lab].get(name, ("", "")))
        rows.append("| " + " | ".join(row) + " |")
    return "\n".join([head, rule, *rows])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true", help="print the table only")
    ap.add_argument("--label", help="this revision's column label (default: the commit)")
    ap.add_argument("--keep", type=int, default=3,
                    help="earlier revisions' columns kept besides the first (default 3)")
    ap.add_argument("--no-build", action="store_true", help="use the example as built")
    args = ap.parse_args()
    if not args.no_build:
        build()
    label = args.label or revision()
    mine: dict[str, tuple[str, str]] = {}
    for name, argv in SCENES:
        total, measure = count(argv)
        mine[name] = (_millions(total), _millions(measure))
        print(f"{name}: {total:,} instructions, measure {measure:,}", file=sys.stderr)
    labels, cells = parse_table(read_block("step-callgrind"))
    labels = [lab for lab in labels if lab != label]
    if len(labels) > 1 + args.keep:
        labels = labels[:1] + labels[len(labels) - args.keep:]
    labels.append(label)
    cells[label] = mine
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    commands = ", ".join(f"`{' '.join(a)}`" for _, a in SCENES)
    body = (
        f"Generated by `python benches/step_callgrind.py` at {label} on {now}: instructions "
        f"of `valgrind --tool=callgrind target/release/examples/step_profile SCENE ...` "
        f"({commands}), in total and in the contact measure (`{MEASURE}`, inclusive). "
        f"Earlier revisions' columns are kept from the previous runs.\n\n"
        + table(labels, cells)
    )
    if args.no_write:
        print(body)
        return 0
    write_block("step-callgrind", body)
    print(body)
    return 0


if __name__ == "__main__":
    sys.exit(main())
