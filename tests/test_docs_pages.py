"""The pages a newcomer looks for first exist, are on the site and agree with the code.

- the CLI reference is generated from the parser the ``skygas`` command runs: every command
  and every option appears in it;
- CITATION.cff names this version;
- the README's own-film example, ``examples/my-film.toml``, is read by the material reader;
- the getting-started page, the CLI reference and the changelog are in the site's navigation.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import sys
from pathlib import Path

import yaml

from skygas._version import __version__
from skygas.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]


def _cli_reference():
    spec = importlib.util.spec_from_file_location(
        "cli_reference", ROOT / "docs" / "hooks" / "cli_reference.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["cli_reference"] = module
    spec.loader.exec_module(module)
    return module


def _every_parser(parser: argparse.ArgumentParser):
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in set(action.choices.values()):
                yield from _every_parser(sub)


def test_the_cli_reference_names_every_command_and_option():
    module = _cli_reference()
    parser = build_parser()
    page = module.cli_reference(parser)
    names = module.command_names(parser)
    assert "skygas reshuffle" in names and "skygas calibrate" in names
    for name in names:
        assert f"\n## {name}\n" in page, name
    options = {
        option
        for sub in _every_parser(parser)
        for action in sub._actions
        if action.help is not argparse.SUPPRESS
        for option in action.option_strings
        if option.startswith("--") and option != "--help"
    }
    assert len(options) > 20
    missing = [o for o in sorted(options) if f"`{o}" not in page and f" {o}" not in page]
    assert missing == []


def test_citation_names_this_version():
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert str(citation["version"]) == __version__
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", str(citation["date-released"]))
    assert citation["references"][0]["doi"] == "10.1103/PhysRevApplied.9.064018"


def test_the_readme_film_example_is_a_film_the_reader_accepts():
    from skygas.calibration.material import load_micromagnetic_material

    assert "examples/my-film.toml" in (ROOT / "README.md").read_text(encoding="utf-8")
    material = load_micromagnetic_material(str(ROOT / "examples" / "my-film.toml"))
    assert material.name == "my-film"
    assert material.cell_size <= material.largest_cell


def test_the_newcomer_pages_are_on_the_site():
    config = yaml.load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"), Loader=yaml.BaseLoader)
    pages = re.findall(r"[\w/.-]+\.md", str(config["nav"]))
    for page in ("getting-started.md", "cli.md", "changelog.md"):
        assert page in pages
        assert (ROOT / "docs" / page).exists()
