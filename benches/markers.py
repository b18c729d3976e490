"""A benchmark's table in BENCHMARKS.md: the text between ``<!-- NAME:begin -->`` and
``<!-- NAME:end -->``, replaced by each run of the script that owns NAME."""

from __future__ import annotations

from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent.parent / "BENCHMARKS.md"


def markers(name: str) -> tuple[str, str]:
    """The begin and end markers of the block NAME."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def read_block(name: str, target: Path = BENCHMARKS) -> str:
    """The current text between the block's markers ("" when the file or block is absent)."""
    text = target.read_text() if target.exists() else ""
    begin, end = markers(name)
    if begin in text and end in text:
        return text[text.index(begin) + len(begin):text.index(end)]
    return ""


def write_block(name: str, body: str, target: Path = BENCHMARKS, *,
                heading: str | None = None, after: str | None = None,
                required: bool = False) -> None:
    """Replace the block NAME's text by ``body``. A file without the block gets it after the
    block ``after`` when that is present, else at the end under ``heading``; with ``required``
    a missing block is an error instead (the table belongs inside prose written around it)."""
    text = target.read_text() if target.exists() else "# Benchmarks\n"
    begin, end = markers(name)
    block = f"{begin}\n{body}\n{end}"
    if begin in text and end in text:
        text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    elif required:
        raise RuntimeError(f"{target} has no {begin} ... {end} block")
    elif after is not None and markers(after)[1] in text:
        anchor = markers(after)[1]
        text = text.replace(anchor, f"{anchor}\n\n{block}", 1)
    else:
        head = f"\n\n{heading}" if heading else ""
        text = text.rstrip("\n") + f"{head}\n\n{block}\n"
    target.write_text(text)
