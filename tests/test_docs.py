"""The docs: the generated references are current, the pages read as a user guide (no
session diaries, dated runs or machine paths), every relative link and anchor resolves, and
CI runs the test command README.md gives. Nothing heavy: the site itself is built by
``mkdocs build --strict`` in the test command."""

from __future__ import annotations

import re
import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"

#: the user guide: README and every page under docs/ (the data folder's notes included)
PAGES = sorted([ROOT / "README.md", *DOCS.rglob("*.md")])
#: pages whose links must resolve (the guide, the changelog, the generated benchmarks page)
LINKED = [*PAGES, ROOT / "CHANGELOG.md", ROOT / "BENCHMARKS.md"]

#: what a lab notebook says and a user guide does not
DIARY = {
    "a session": re.compile(r"\bsessions?\b", re.IGNORECASE),
    "an issue number": re.compile(r"\bissues?\s+#?\d+", re.IGNORECASE),
    "a date": re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b"),
    "a clock-time range": re.compile(r"\b[0-2]?\d:[0-5]\d\s*(?:-|->|–)\s*[0-2]?\d:[0-5]\d\b"),
    "a machine path": re.compile(r"(?<![\w.])/(?:work|tmp|root|home)/"),
}

_FENCE = re.compile(r"^(```|~~~)")
_LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def rel(path: Path) -> str:
    return str(path.relative_to(ROOT))


def prose(path: Path) -> list[tuple[int, str]]:
    """(line number, line) of a markdown file outside fenced code blocks."""
    out, fenced = [], False
    for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if _FENCE.match(line.strip()):
            fenced = not fenced
            continue
        if not fenced:
            out.append((i, line))
    return out


def github_slug(heading: str) -> str:
    """The anchor GitHub gives a heading: markdown stripped, lower case, punctuation other
    than hyphens and underscores dropped, each space a hyphen."""
    text = re.sub(r"`([^`]*)`", r"\1", heading)
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[*_]{1,2}([^*_]+)[*_]{1,2}", r"\1", text)
    text = text.strip().lower()
    text = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN")
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The anchors of a markdown file's headings (GitHub's, numbered when repeated)."""
    seen: dict[str, int] = {}
    out = set()
    for _, line in prose(path):
        m = _HEADING.match(line)
        if not m:
            continue
        slug = github_slug(m.group(2))
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


def test_the_generated_references_are_current() -> None:
    """docs/reference/config.md and cli.md are what tools/config_reference.py makes of the
    config models and the commands (run it after changing either)."""
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "config_reference.py"), "--check"],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr


def test_the_config_reference_has_every_key() -> None:
    """Every key of the config models has a row, with a description."""
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import config_reference as gen
    finally:
        sys.path.remove(str(ROOT / "tools"))
    from tribodem.braking import BrakingConfig
    from tribodem.dem import DemRunConfig
    from tribodem.fretting import FrettingConfig

    page = (DOCS / "reference" / "config.md").read_text(encoding="utf-8")
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| `([^`]+)` \|(.*)\|$", page, re.M)}

    def keys(model, prefix=""):  # noqa: ANN001, ANN202
        for name, f in model.model_fields.items():
            if f.exclude:  # internal, not a key of a config file
                continue
            if gen.is_model(f.annotation):
                yield from keys(f.annotation, f"{prefix}{name}.")
            else:
                yield f"{prefix}{name}"

    for model in (FrettingConfig, BrakingConfig, DemRunConfig):
        for key in keys(model):
            assert key in rows, f"{key} has no row in docs/reference/config.md"
            description = rows[key].rstrip().rsplit("|", 1)[-1].strip()
            assert description, f"{key} has no description (give its Field a description)"


def test_every_key_of_the_docs_toml_is_in_the_reference() -> None:
    """A newcomer finds every config key a page shows them (the ```toml blocks of the
    guide) in the configuration reference."""
    import tomllib

    page = (DOCS / "reference" / "config.md").read_text(encoding="utf-8")
    rows = set(re.findall(r"^\| `([^`]+)` \|", page, re.M))

    def flat(d, prefix=""):  # noqa: ANN001, ANN202
        for k, v in d.items():
            if isinstance(v, dict) and f"{prefix}{k}" not in rows:
                yield from flat(v, f"{prefix}{k}.")
            else:
                yield f"{prefix}{k}"

    missing = []
    for path in PAGES:
        text = path.read_text(encoding="utf-8")
        for block in re.findall(r"^```toml\n(.*?)^```", text, re.M | re.S):
            missing += [f"{rel(path)}: {k}" for k in flat(tomllib.loads(block)) if k not in rows]
    assert not missing, "\n".join(missing)


@pytest.mark.parametrize("path", LINKED, ids=rel)
def test_no_diary_session_date_or_machine_path(path: Path) -> None:
    """A page says what is, not when or where it was measured (history lives in git, the
    CHANGELOG and the issue notes). BENCHMARKS.md's table states when each row was
    measured (a date column, durations in its notes) by design."""
    hits = []
    for i, line in prose(path):
        for what, pattern in DIARY.items():
            if path.name == "BENCHMARKS.md" and what in ("a date", "a clock-time range"):
                continue
            m = pattern.search(line)
            if m:
                hits.append(f"{rel(path)}:{i}: {what}: {m.group(0)!r}")
    assert not hits, "\n".join(hits)


@pytest.mark.parametrize("path", LINKED, ids=rel)
def test_relative_links_resolve(path: Path) -> None:
    """Every relative link of a page points to a file of the repository, and an anchor
    into a markdown file to one of its headings."""
    bad = []
    for i, line in prose(path):
        for m in _LINK.finditer(line):
            target = m.group(1)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("/"):
                continue
            name, _, anchor = target.partition("#")
            dest = (path.parent / name).resolve() if name else path
            if not dest.exists():
                bad.append(f"{rel(path)}:{i}: {target}: no such file")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                bad.append(f"{rel(path)}:{i}: {target}: no heading #{anchor} in {rel(dest)}")
    assert not bad, "\n".join(bad)


def _fenced_commands(path: Path) -> list[str]:
    """The lines of the ```bash blocks of a markdown file."""
    out, block = [], None
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            block = [] if block is None and line.strip() == "```bash" else None
            continue
        if block is not None and line.strip():
            out.append(line.strip())
    return out


def test_readme_starts_with_the_two_commands_and_ci_runs_the_second() -> None:
    commands = _fenced_commands(ROOT / "README.md")
    assert commands[0] == ("bash tools/setup && .venv/bin/tribodem fretting run --quick "
                           "--out runs/demo")
    test_command = commands[1]
    assert test_command.startswith(
        "bash tools/setup && .venv/bin/ruff check . && .venv/bin/lint-imports && "
        ".venv/bin/python -m pytest -q -n auto --dist loadfile")
    assert ".venv/bin/mkdocs build --strict" in test_command
    ci = [line.strip() for line in (ROOT / ".ci" / "run").read_text().splitlines()
          if line.strip() and not line.lstrip().startswith("#")]
    assert test_command in ci, ".ci/run must run README.md's test command, exactly"
