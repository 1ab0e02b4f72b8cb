"""Writing a benchmark's result into its docs page: the text between the page's two markers replaced."""
from __future__ import annotations

from pathlib import Path


def replace_block(path: Path, begin: str, end: str, block: str) -> None:
    """Put ``block`` (a text block, fenced here) between the markers ``begin`` and ``end`` of ``path``;
    SystemExit naming them where the page lacks them."""
    text = path.read_text(encoding="utf-8")
    if begin not in text or end not in text:
        raise SystemExit(f"{path}: no {begin} ... {end} block to replace")
    head, rest = text.split(begin, 1)
    _old, tail = rest.split(end, 1)
    path.write_text(f"{head}{begin}\n```text\n{block}\n```\n{end}{tail}", encoding="utf-8")
