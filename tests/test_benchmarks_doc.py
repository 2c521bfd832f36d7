"""docs/benchmarks.md states the present: one section per benchmark script, short, with no run diary.

The page gives, per ``benchmarks/bench_*.py``, what it measures, the command, the latest recorded figures with
their date and load, and the goals; how the figures came about is git's history, not the page's. These checks
keep it that way: a length cap, no commit hashes, branch names or issue numbers, no diary narration, one
``##`` section per script (and only for scripts that exist), each with its "not re-measured since DATE" mark
and a command whose options the script defines.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "benchmarks.md"
BENCH = ROOT / "benchmarks"
MAX_LINES = 600

#: a commit-hash-like token: 7 to 40 hex digits with at least one decimal digit (so that words such as "defaced"
#: pass; numbers are written with spaced thousands, "235 415", so a bare run of 7+ digits is a hash too)
HASH = re.compile(r"(?<![\w.])(?=[0-9a-fA-F]*[0-9])[0-9a-fA-F]{7,40}(?![\w])")
#: branch names: the project's session branches ("s36-bbf", "s37-orb"), a git branch spoken of ("on the branch",
#: "branch `ch08`"; a kd-tree's "branch" stays allowed) and "main" used as a ref ("on main", "main:path")
BRANCH = re.compile(r"\bs\d{1,3}-[a-z][a-z0-9-]*\b|\b(?:on|in|from) (?:the |a |this |that )?branch(?:es)?\b|"
                    r"\bbranch `[^`]+`|\b(?:on|of|from|at) main\b|\bmain:|\bmain [0-9a-f]{7}", re.IGNORECASE)
#: issue numbers: "issue 25", "issues 22 and 28", "#25"
ISSUE = re.compile(r"\bissues?\s*#?\s*\d+|(?<![\w&])#\d+\b", re.IGNORECASE)
#: diary words. Each one narrates how the page's figures or the code changed over time instead of saying what
#: holds now; the list is small and explicit so that ordinary present-tense words ("since" in "not re-measured
#: since", "beforehand") stay allowed:
#: - "previously", "earlier", "used to", "no longer", "before the fix", "was fixed", "for the record", "today":
#:   comparisons with a former state of the code or of the page (git keeps those states);
#: - "stop <n>": the project's name for a work session, meaningless to a reader of the page;
#: - "was ... now": the "it was X, now it is Y" pattern of a changelog.
DIARY = re.compile(r"\bpreviously\b|\bearlier\b|\bused to\b|\bno longer\b|\bbefore the fix\b|\bwas fixed\b|"
                   r"\bfor the record\b|\btoday\b|\bstop \d+\b|\bwas\b[^\n]{0,60}?\bnow\b", re.IGNORECASE)
#: a section's "not re-measured since" mark with its date
MARK = re.compile(r"not re-measured since \d{4}-\d{2}-\d{2}", re.IGNORECASE)
SCRIPT = re.compile(r"benchmarks/([A-Za-z0-9_]+\.py)")


def _text() -> str:
    return DOC.read_text(encoding="utf-8")


def _sections(text: str) -> list[tuple[str, str]]:
    """(heading, body) of every ``##`` section (``###`` subsections stay in their section's body)."""
    parts = re.split(r"^## (.*)$", text, flags=re.MULTILINE)
    return [(parts[i].strip(), parts[i + 1]) for i in range(1, len(parts), 2)]


def _hits(pattern: re.Pattern, text: str) -> list[str]:
    return [f"line {text.count(chr(10), 0, m.start()) + 1}: {m.group(0)!r}" for m in pattern.finditer(text)]


def test_page_is_at_most_600_lines():
    n = len(_text().splitlines())
    assert n <= MAX_LINES, f"docs/benchmarks.md has {n} lines (at most {MAX_LINES}): state the present, git keeps the rest"


@pytest.mark.parametrize(("name", "pattern"), [("commit-hash-like token", HASH), ("branch name", BRANCH),
                                           ("issue number", ISSUE), ("diary word", DIARY)])
def test_page_has_no_history(name, pattern):
    hits = _hits(pattern, _text())
    assert not hits, f"docs/benchmarks.md contains a {name}:\n" + "\n".join(hits[:20])


def test_patterns_catch_what_they_are_for():
    """The patterns themselves: each catches its kind and lets the page's ordinary figures through."""
    assert HASH.search("at 3b4cfb3, load 1.0")
    assert HASH.search("commit 1234567")
    assert not HASH.search("235 415 landmarks, 0.0362 s, 4e-4, 2026-11-27, defaced, 1.0054")
    for text in ("on s36-bbf", "measured on the branch", "branch `ch08`", "git show main:x.py", "run on main"):
        assert BRANCH.search(text), text
    assert not BRANCH.search("the main cause, the domain, the far branch's cell")
    for text in ("issue 25's goals", "Issues 22 and 28", "see #42"):
        assert ISSUE.search(text), text
    for text in ("stop 38", "it was 2.1x, now 1.3x", "previously"):
        assert DIARY.search(text), text
    assert not DIARY.search("not re-measured since 2026-11-22; rendered beforehand")


def test_one_section_per_benchmark_script():
    sections = _sections(_text())
    named = {}
    for heading, _ in sections:
        scripts = SCRIPT.findall(heading)
        assert len(scripts) == 1, f"section {heading!r} must name exactly one benchmarks/bench_*.py script"
        assert scripts[0] not in named, f"two sections for {scripts[0]}"
        named[scripts[0]] = heading
    existing = {p.name for p in BENCH.glob("bench_*.py")}
    assert existing, "no benchmarks/bench_*.py found"
    missing = sorted(existing - set(named))
    unknown = sorted(set(named) - existing)
    assert not missing, f"benchmark scripts without a section in docs/benchmarks.md: {missing}"
    assert not unknown, f"sections for scripts that do not exist (or are not bench_*.py): {unknown}"


def test_every_script_the_page_names_exists():
    missing = sorted({s for s in SCRIPT.findall(_text()) if not (BENCH / s).is_file()})
    assert not missing, f"docs/benchmarks.md names scripts that do not exist: {missing}"


def test_every_section_is_dated_and_has_a_command_the_script_accepts():
    for heading, body in _sections(_text()):
        script = SCRIPT.findall(heading)[0]
        assert MARK.search(body), f"section {heading!r} has no 'not re-measured since YYYY-MM-DD' mark"
        source = (BENCH / script).read_text(encoding="utf-8")
        blocks = re.findall(r"^```[^\n]*\n(.*?)^```", body, flags=re.MULTILINE | re.DOTALL)
        commands = [line for block in blocks for line in block.splitlines() if f"benchmarks/{script}" in line]
        assert commands, f"section {heading!r} has no command running benchmarks/{script} in a code block"
        for line in commands:
            for other in SCRIPT.findall(line):  # options belong to the script the line runs
                src = (BENCH / other).read_text(encoding="utf-8")
                call = line.split(f"benchmarks/{other}", 1)[1].split("#", 1)[0]
                for option in re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", call):
                    assert f'"{option}"' in src, f"{other} has no option {option} (section {heading!r}): {line}"
            assert source  # the section's own script was read
