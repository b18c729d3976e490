"""The user guide's code examples (``>>>`` blocks in docs/guide/*.md) run and print what the
guide says they print."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import pytest

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide"
PAGES = sorted(GUIDE.glob("*.md"))
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def _examples(page: Path) -> str:
    """The page's Python blocks written as doctest sessions, joined in order (a page shares
    its names from block to block, as a reader's session would)."""
    blocks = [b for b in FENCE.findall(page.read_text()) if b.lstrip().startswith(">>>")]
    return "\n".join(blocks)


def test_guide_has_examples() -> None:
    assert any(_examples(p) for p in PAGES), f"no >>> examples in {GUIDE}"


@pytest.mark.parametrize("page", [p for p in PAGES if _examples(p)], ids=lambda p: p.name)
def test_guide_examples_run(page: Path) -> None:
    parser = doctest.DocTestParser()
    test = parser.get_doctest(_examples(page), {}, page.name, str(page), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    failed, attempted = runner.summarize(verbose=False)
    assert attempted > 0
    assert failed == 0, f"{failed} of {attempted} examples in {page.name} fail (output above)"
