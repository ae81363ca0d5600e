"""House rules for the library's text (STYLE.md §8-9): docstrings and comments say what, units,
shapes, defaults and references; they carry no dates and no issue numbers (history belongs in git,
measurements in benchmarks/RESULTS.md), and no module grows past ``MAX_MODULE_LINES``.

Read from the source files, so every module is checked whether a test imports it or not. Only
``.py`` files are scanned: the data files in ``jaxgear/data`` are written by their benchmarks
(``fidelity_errors.json`` by ``benchmarks/fidelity_trade.py``) and record their provenance, dates
included, on purpose."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import jaxgear

ROOT = Path(jaxgear.__file__).resolve().parent
MAX_MODULE_LINES = 900

ISO_DATE = re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b")
ISSUE_REFERENCE = re.compile(r"\bissues?\s+#?\d+", re.IGNORECASE)


def _sources() -> list[Path]:
    files = sorted(ROOT.rglob("*.py"))
    assert len(files) > 50, f"found only {len(files)} modules under {ROOT}"
    return files


def _where(path: Path) -> str:
    return str(path.relative_to(ROOT.parent))


def test_patterns_catch_what_they_are_for():
    """The checks below cannot pass silently: each pattern finds its samples and leaves plain text
    alone."""
    for text in ("measured 2026-11-28", "(2025-01-09)", "as of 2031-12-31, the"):
        assert ISO_DATE.search(text), text
    for text in ("2026-1-5", "a 2x2-10-100 grid", "ISO 16610-21", "1025-2049 nodes"):
        assert not ISO_DATE.search(text), text
    for text in ("see issue 57", "(issues 12 and 13)", "Issue #7:", "ISSUES 3"):
        assert ISSUE_REFERENCE.search(text), text
    for text in ("an issue tracker", "the issue is the grid", "REFERENCE §4", "tissue 5"):
        assert not ISSUE_REFERENCE.search(text), text


def test_no_dates_or_issue_numbers_in_the_library():
    """No ISO date and no "issue N" anywhere in a module: code, comments, docstrings, strings."""
    offenders = []
    for path in _sources():
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            for pattern, what in ((ISO_DATE, "date"), (ISSUE_REFERENCE, "issue reference")):
                match = pattern.search(line)
                if match:
                    offenders.append(f"{_where(path)}:{number}: {what} {match.group(0)!r}")
    assert not offenders, "dates or issue numbers in jaxgear/ (move them to git history):\n" + (
        "\n".join(offenders)
    )


def test_no_module_is_too_long():
    """Every module stays at most ``MAX_MODULE_LINES`` lines: one concept per file (STYLE.md §2)."""
    lengths = {
        _where(path): len(path.read_text(encoding="utf-8").splitlines()) for path in _sources()
    }
    assert max(lengths.values()) > 100, "line counting is broken"
    long = {name: n for name, n in lengths.items() if n > MAX_MODULE_LINES}
    assert not long, f"modules over {MAX_MODULE_LINES} lines: " + ", ".join(
        f"{name} ({n} lines)" for name, n in sorted(long.items())
    )


REPO = ROOT.parent
MAX_README_LINES = 150


def test_readme_is_a_users_page():
    """The README stays a user's page: at most ``MAX_README_LINES`` lines, dates only in a
    "measured on" note, and its test command is the one CI runs (``.ci/run``)."""
    readme = REPO / "README.md"
    if not readme.exists():  # an installed package without its repository
        pytest.skip("README.md is not beside the package")
    lines = readme.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_README_LINES, f"README.md has {len(lines)} lines"
    dated = [
        f"README.md:{n}: {line.strip()}"
        for n, line in enumerate(lines, start=1)
        if ISO_DATE.search(line) and "measured on" not in line
    ]
    assert not dated, "dates outside a 'measured on' note:\n" + "\n".join(dated)
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    command = '.venv/bin/pip install -e ".[test]" && .venv/bin/python -m pytest'
    assert command in ci and command in "\n".join(lines)
