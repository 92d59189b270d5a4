"""Every citation of the model specification resolves: docs/model.md, by path, to a section it has.

Docstrings and comments cite the spec as ``docs/model.md §N`` or ``docs/model.md §N.M`` (several
sections: ``docs/model.md §2, §3``). A citation that names the file any other way (bare, or
another copy of it) or a section that is not a heading of docs/model.md fails here, so a
renumbered or removed section cannot leave readers pointing at nothing.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CITED_PATH = "docs/model.md"
SPEC = ROOT / CITED_PATH

# Any mention of the spec file, with whatever path is written before it.
_MENTION = re.compile(r"[\w./-]*model\.md")
# The sections following one mention: "§2", "§2, §3", "§2 and §4.1", "§5's".
_SECTIONS = re.compile(r"model\.md((?:\s*(?:,|and|/)?\s*§\s*\d+(?:\.\d+)*)+)")
_NUMBER = re.compile(r"§\s*(\d+(?:\.\d+)*)")
_HEADING = re.compile(r"^#{2,6}\s+(\d+(?:\.\d+)*)\.?\s")


def spec_sections() -> set[str]:
    """Section numbers that are headings of docs/model.md: ``{"1", "1.1", ..., "7.2"}``."""
    return {m.group(1) for line in SPEC.read_text().splitlines() if (m := _HEADING.match(line))}


def python_files() -> list[Path]:
    """Every ``.py`` file of the checkout, outside .venv, .git and other hidden or cache folders."""
    found = []
    for folder, subfolders, files in os.walk(ROOT):
        subfolders[:] = sorted(d for d in subfolders if not d.startswith(".") and d != "__pycache__")
        found.extend(Path(folder, name) for name in sorted(files) if name.endswith(".py"))
    return found


def citations() -> list[tuple[str, int, str]]:
    """``(file, line number, line)`` for every line that mentions the spec file."""
    out = []
    for path in python_files():
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            if _MENTION.search(line):
                out.append((str(path.relative_to(ROOT)), number, line))
    return out


def test_the_spec_keeps_its_numbered_sections():
    """Sections 1-6 of the original specification keep their numbers (docstrings cite them)."""
    assert {"1", "2", "3", "4", "5", "6"} <= spec_sections()


def test_citations_name_the_spec_by_its_path():
    bad = [
        f"{file}:{number}: cites {mention!r}, not {CITED_PATH!r}"
        for file, number, line in citations()
        for mention in _MENTION.findall(line)
        if mention != CITED_PATH
    ]
    assert not bad, "citations of the spec must read docs/model.md:\n" + "\n".join(bad)


def test_every_cited_section_exists():
    sections = spec_sections()
    bad = [
        f"{file}:{number}: §{section} is not a heading of docs/model.md"
        for file, number, line in citations()
        for cited in _SECTIONS.findall(line)
        for section in _NUMBER.findall(cited)
        if section not in sections
    ]
    assert not bad, "cited sections missing from docs/model.md:\n" + "\n".join(bad)
