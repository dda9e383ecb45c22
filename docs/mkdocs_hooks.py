"""mkdocs hooks (``hooks:`` in mkdocs.yml): the repository's own pages in the site.

The docs link to files at the repository root with paths that work when the markdown is
read in the repository (``../BENCHMARKS.md``, ``../CHANGELOG.md``). mkdocs knows only the
files under ``docs/``, so in strict mode such a link would fail the build. These hooks add
the root files of :data:`MIRRORED` to the site (``benchmarks.md`` ...) and rewrite every
relative link that leaves ``docs/``: to the mirrored page when it points at one, else to
the file's path in the repository as code (the site has no copy of it). Links inside the
mirrored pages, written relative to the repository root, are rewritten the same way.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

#: repository file -> its page in the site
MIRRORED = {"BENCHMARKS.md": "benchmarks.md", "CHANGELOG.md": "changelog.md"}

_LINK = re.compile(r"(?<!!)\[([^\]]*)\]\(([^)\s]+)\)")


def _root(config: Any) -> Path:
    return Path(config["docs_dir"]).resolve().parent


def on_files(files: Files, config: Any) -> Files:
    root = _root(config)
    for src, page in MIRRORED.items():
        path = root / src
        if path.is_file():
            files.append(File.generated(config, page, abs_src_path=str(path)))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    root = _root(config)
    docs = Path(config["docs_dir"]).resolve()
    page_uri = page.file.src_uri
    mirrored_from = {v: k for k, v in MIRRORED.items()}.get(page_uri)
    # where the markdown's relative links start: the repository root for a mirrored page
    base = root if mirrored_from else (docs / page_uri).parent
    here = (docs / page_uri).parent

    def fix(m: re.Match[str]) -> str:
        text, target = m.group(1), m.group(2)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
            return m.group(0)
        path, _, anchor = target.partition("#")
        dest = (base / path).resolve()
        if dest.is_relative_to(docs):
            if not mirrored_from:
                return m.group(0)
            rel = Path(dest.relative_to(docs)).as_posix()
        else:
            try:
                repo_path = dest.relative_to(root).as_posix()
            except ValueError:
                return m.group(0)
            if repo_path not in MIRRORED:
                return f"{text} (`{repo_path}`)" if text and text != repo_path else \
                    f"`{repo_path}`"
            rel = MIRRORED[repo_path]
        link = Path(rel).as_posix()
        link = _relative(docs / link, here)
        return f"[{text}]({link}{'#' + anchor if anchor else ''})"

    return _LINK.sub(fix, markdown)


def _relative(dest: Path, here: Path) -> str:
    import os

    return Path(os.path.relpath(dest, here)).as_posix()
