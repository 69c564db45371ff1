"""MkDocs hooks of the documentation site (mkdocs.yml, ``hooks:``).

- The home page is the README: ``index.md`` is replaced by its text, with its links into
  ``docs/`` made relative to the site's pages.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def on_page_markdown(markdown: str, page, config, files) -> str:
    """The README as the home page."""
    if page.file.src_uri != "index.md":
        return markdown
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    return re.sub(r"\]\(docs/", "](", readme)
