"""Griffe extension for the API pages: the docstrings' Sphinx roles as cross-references.

The docstrings are written for numpydoc and Sphinx (:func:`name`, :class:`~pkg.Name`,
:math:`x`). mkdocstrings reads them as Markdown, where a role would show as literal text. This
extension rewrites each role before the docstring is parsed: an object role becomes the name
as code, linked to the object's page where the site documents it (an optional cross-reference:
a name without a page stays plain code, with no warning); :math: becomes code. A unit in
brackets followed by another bracket ("in [start, end] [s]") would read as a Markdown reference
link: its bracket is escaped.
"""

from __future__ import annotations

import html
import re
from typing import Any

import griffe

ROLE = re.compile(
    r":(?:py:)?(?P<role>func|class|meth|mod|data|attr|exc|obj|const|math):"
    r"`(?P<text>[^`]+)`"
)
UNIT_AFTER_BRACKET = re.compile(r"\] \[")
TITLED = re.compile(r"^(?P<title>.+?)\s*<(?P<target>[^<>]+)>$")


def _resolve(obj: griffe.Object, target: str) -> str:
    """The full path of ``target`` as written in ``obj``'s docstring (best effort)."""
    name = target.lstrip(".")
    if name.startswith("skygas.") or name == "skygas":
        return name
    head, _, rest = name.partition(".")
    scope: Any = obj
    while scope is not None:
        try:
            path = scope.resolve(head)
        except Exception:  # noqa: BLE001 - unresolved: try the enclosing scope
            scope = scope.parent
            continue
        return f"{path}.{rest}" if rest else path
    # a submodule named relative to the object's package (:mod:`.neighbors`)
    module = obj if obj.is_module else obj.module
    package = module.path if module.is_package else module.path.rpartition(".")[0]
    return f"{package}.{name}"


def _rewrite(obj: griffe.Object, text: str) -> str:
    def replace(match: re.Match) -> str:
        role, body = match["role"], match["text"]
        if role == "math":
            return f"<code>{html.escape(body)}</code>"
        titled = TITLED.match(body)
        if titled:
            title, target = titled["title"], titled["target"]
        else:
            target = body.removesuffix("()")
            short = target.startswith("~")
            target = target.lstrip("~")
            title = target.lstrip(".").rpartition(".")[2] if short else target.lstrip(".")
            if role in ("func", "meth"):
                title += "()"
        path = _resolve(obj, target.lstrip("~").removesuffix("()"))
        return (
            f'<autoref identifier="{html.escape(path)}" optional>'
            f"<code>{html.escape(title)}</code></autoref>"
        )

    # outside code spans (the odd pieces between backticks), "] [" must not make a link
    pieces = text.split("`")
    pieces[::2] = [UNIT_AFTER_BRACKET.sub(r"] \\[", piece) for piece in pieces[::2]]
    return ROLE.sub(replace, "`".join(pieces))


class SphinxRoles(griffe.Extension):
    """Rewrite the Sphinx roles of every docstring of a loaded package."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        """Walk the package's objects (not the aliases) once it is loaded."""
        seen: set[int] = set()
        stack: list[griffe.Object] = [pkg]
        while stack:
            obj = stack.pop()
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            if obj.docstring is not None:
                obj.docstring.value = _rewrite(obj, obj.docstring.value)
            stack.extend(m for m in obj.members.values() if not m.is_alias)
