"""MkDocs hooks of the documentation site (mkdocs.yml, ``hooks:``).

Three pages are written at build time, so that none of them is a copy that can fall behind:

- the home page (``index.md``) is the README, with its links into ``docs/`` made relative to
  the site's pages;
- the command-line reference (``cli.md``) is generated from ``skygas.cli.build_parser()``
  (:mod:`cli_reference`, beside this file);
- the changelog (``changelog.md``) is the repository's ``CHANGELOG.md``.
"""

from __future__ import annotations

import re
from pathlib import Path

# MkDocs puts this file's folder on sys.path while it loads the hook.
from cli_reference import cli_reference

ROOT = Path(__file__).resolve().parents[2]


def _home() -> str:
    """The README as the home page."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    return re.sub(r"\]\(docs/", "](", readme)


def _cli() -> str:
    """The command-line reference, from the parser the ``skygas`` command runs."""
    from skygas.cli import build_parser

    return cli_reference(build_parser())


def _changelog() -> str:
    """CHANGELOG.md as it is in the repository."""
    return (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")


#: the pages written here, by their path under docs/
GENERATED = {"index.md": _home, "cli.md": _cli, "changelog.md": _changelog}


#: A table cell that shows a missing number as if it were one (``nan %``, ``None nm``).
_MISSING_NUMBER = re.compile(r"<td>\s*(?:nan|NaN|None|inf)\s*(?:%|[nµm]?m|[nµm]?s|K|T|A/m²)?\s*</td>")


def on_post_page(output: str, page, config) -> str:
    """Refuse a page whose table shows a missing number as a value: the site is not built."""
    from mkdocs.exceptions import PluginError

    found = _MISSING_NUMBER.search(output)
    if found:
        raise PluginError(f"{page.file.src_uri}: a table cell shows {found.group(0)!r}")
    return output


def on_page_markdown(markdown: str, page, config, files) -> str:
    """The generated pages' text in place of their placeholders."""
    make = GENERATED.get(page.file.src_uri)
    return markdown if make is None else make()
