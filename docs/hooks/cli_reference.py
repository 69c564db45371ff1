"""The command-line reference page (docs/cli.md), written from the argparse tree at build time.

:func:`cli_reference` walks ``skygas.cli.build_parser()``: every sub-command (nested ones such as
``skygas sc demo`` too) with its one-line help, description, usage, arguments (each with its
help and default) and example. The page is generated at each ``make docs``, so it says what
``skygas COMMAND --help`` says and cannot fall behind the code. argparse has no public API
for walking a parser, so its documented-in-practice attributes (``_actions``,
``_action_groups``, ``choices``) are read, and its own formatter writes the usage line and
the ``%(default)s``-style expansions, so that the text is the one ``--help`` prints.
"""

from __future__ import annotations

import argparse
import html
import re
from collections.abc import Iterator

#: the program name the reference is written for
PROG = "skygas"

_CODE_SPAN = re.compile(r"(`[^`]*`)")


def _text(value: str) -> str:
    """Help text as Markdown inside a table cell: one line, code spans kept, the rest escaped.

    Outside code spans, ``*``, ``_``, ``[`` and ``<`` would start emphasis, links or HTML
    (``m*.ovf``, ``<field>``); ``|`` would end the cell (``|j|``) anywhere.
    """
    parts = []
    for part in _CODE_SPAN.split(" ".join(value.split())):
        if part.startswith("`") and part.endswith("`") and len(part) > 1:
            parts.append(part.replace("|", "\\|"))
        else:
            escaped = html.escape(part, quote=False)
            parts.append(re.sub(r"([\\*_\[\]|])", r"\\\1", escaped))
    return "".join(parts)


def _code(value: str) -> str:
    """A value as a Markdown code span, safe in a table cell."""
    value = value.replace("|", "\\|")
    fence = "``" if "`" in value else "`"
    return f"{fence}{value}{fence}"


def _subcommands(
    parser: argparse.ArgumentParser, prefix: str
) -> Iterator[tuple[str, str, argparse.ArgumentParser]]:
    """(full name, one-line help, parser) of every sub-command under ``parser``, depth first."""
    for action in parser._actions:
        if not isinstance(action, argparse._SubParsersAction):
            continue
        helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
        seen: set[int] = set()
        for name, sub in action.choices.items():
            if id(sub) in seen:  # an alias of a command already listed
                continue
            seen.add(id(sub))
            full = f"{prefix} {name}"
            yield full, helps.get(name, ""), sub
            yield from _subcommands(sub, full)


def command_names(parser: argparse.ArgumentParser) -> list[str]:
    """Every sub-command of ``parser`` as typed (``"skygas reshuffle"``, ``"skygas sc demo"``)."""
    return [name for name, _, _ in _subcommands(parser, parser.prog)]


def _anchor(name: str) -> str:
    """The heading id that the toc extension gives ``## name`` (words joined by ``-``)."""
    return "-".join(name.lower().split())


def _default(action: argparse.Action) -> str:
    """The default of an argument as the reference shows it ("required" for a required option)."""
    if action.required and action.option_strings:
        return "required"
    if isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction)):
        return "off" if isinstance(action, argparse._StoreTrueAction) else "on"
    default = action.default
    if default is None or default is argparse.SUPPRESS:
        return "—"
    if isinstance(default, (list, tuple)):
        return _code(" ".join(str(item) for item in default))
    return _code(str(default))


def _help(formatter: argparse.HelpFormatter, action: argparse.Action) -> str:
    """An argument's help with argparse's ``%(...)s`` expanded, and its choices."""
    text = formatter._expand_help(action) if action.help else ""
    if action.choices is not None and action.metavar is not None:
        # argparse shows the choices only when there is no metavar: say them here.
        listed = ", ".join(_code(str(choice)) for choice in action.choices)
        return f"{_text(text)} (one of {listed})".strip()
    return _text(text)


def _arguments_table(parser: argparse.ArgumentParser) -> list[str]:
    """One table per argument group (positional arguments, options), ``--help`` left out."""
    formatter = argparse.HelpFormatter(parser.prog)
    lines: list[str] = []
    for group in parser._action_groups:
        rows = []
        for action in group._group_actions:
            if (
                action.help is argparse.SUPPRESS
                or isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))
            ):
                continue
            invocation = formatter._format_action_invocation(action)
            meaning, default = _help(formatter, action), _default(action)
            rows.append(f"| {_code(invocation)} | {meaning} | {default} |")
        if rows:
            lines += [f"**{group.title}**", "", "| argument | meaning | default |", "|---|---|---|"]
            lines += [*rows, ""]
    return lines


def _usage(parser: argparse.ArgumentParser) -> str:
    """The usage line as ``--help`` writes it, wrapped at 90 columns whatever the terminal."""
    formatter = argparse.HelpFormatter(parser.prog, width=90)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups, "")
    return formatter.format_help().strip()


def _command_section(name: str, summary: str, parser: argparse.ArgumentParser) -> list[str]:
    lines = [f"## {name}", ""]
    if summary:
        lines += [_text(summary[0].upper() + summary[1:]) + ".", ""]
    if parser.description:
        lines += [_text(parser.description), ""]
    lines += ["```text", _usage(parser), "```", ""]
    depth = name.count(" ") + 1
    children = [
        (full, text) for full, text, _ in _subcommands(parser, name) if full.count(" ") == depth
    ]
    if children:
        lines += ["Sub-commands:", ""]
        lines += [f"- [`{full}`](#{_anchor(full)}): {_text(text)}" for full, text in children]
        lines.append("")
    lines += _arguments_table(parser)
    if parser.epilog:
        title, _, body = parser.epilog.partition("\n")
        if title.rstrip(":") == "example" and body.strip():
            lines += ["Example:", "", "```", body.strip(), "```", ""]
        else:
            lines += [_text(parser.epilog), ""]
    return lines


def cli_reference(parser: argparse.ArgumentParser) -> str:
    """The command-line reference of ``parser`` (``skygas.cli.build_parser()``) as Markdown."""
    commands = list(_subcommands(parser, parser.prog))
    lines = [
        "# Command-line reference",
        "",
        f"Every `{parser.prog}` command with its arguments, their meaning and default. This page is "
        "written from the command line's own definition each time the site is built, so it "
        f"says what `{parser.prog} COMMAND --help` says. Every command also takes `-h`/`--help`.",
        "",
        "```text",
        _usage(parser),
        "```",
        "",
    ]
    if parser.epilog:
        lines += [_text(parser.epilog), ""]
    lines += _arguments_table(parser)
    lines += ["| command | what it does |", "|---|---|"]
    lines += [f"| [`{name}`](#{_anchor(name)}) | {_text(text)} |" for name, text, _ in commands]
    lines.append("")
    for name, summary, sub in commands:
        lines += _command_section(name, summary, sub)
    return "\n".join(lines)
