"""The command line's options: one style across commands, a help line each, the README's tour.

Walks the argparse tree of ``skygas`` (every command and sub-command) instead of listing the
commands, so a new command or option is covered without editing this file.
"""

from __future__ import annotations

import argparse
import json
import re
import shlex
from pathlib import Path

import pytest

from skygas.cli import build_parser, main
from skygas.commands.json_output import INDENT, json_text
from skygas.micromag.samples import folder
from skygas.runs.checkpoint_interval import CHECKPOINT_SECONDS

ROOT = Path(__file__).resolve().parents[2]


def _commands(parser: argparse.ArgumentParser, prefix: str = "skygas"):
    """Every (command line prefix, parser) of the tree, ``skygas`` itself included."""
    yield prefix, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, f"{prefix} {name}")


def _options(parser: argparse.ArgumentParser) -> dict[str, argparse.Action]:
    return {
        action.option_strings[-1] if action.option_strings else action.dest: action
        for action in parser._actions
        if not isinstance(action, argparse._SubParsersAction)
    }


COMMANDS = dict(_commands(build_parser()))


def test_every_option_of_every_command_has_a_help_line():
    missing = [
        f"{name} {option}"
        for name, parser in COMMANDS.items()
        for option, action in _options(parser).items()
        if action.help is None or not str(action.help).strip()
    ]
    for parser in COMMANDS.values():  # and every sub-command its line in its parent's list
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                missing += [c.dest for c in action._choices_actions if not (c.help or "").strip()]
    assert missing == []
    assert len(COMMANDS) > 20  # the walk reaches the sub-commands (sc demo, micromag fit, ...)


def test_every_json_option_is_the_one_helper_and_prints_indented_standard_json(capsys):
    with_json = [name for name, p in COMMANDS.items() if "--json" in _options(p)]
    # every command that prints a result has it; those that write one file print one line
    expected = {
        "skygas simulate",
        "skygas check-timestep",
        "skygas demo",
        "skygas reshuffle",
        "skygas neuron",
        "skygas saturation",
        "skygas reservoir",
        "skygas sweep",
        "skygas plot",
        "skygas analyze",
        "skygas sc demo",
        "skygas micromag inspect",
        "skygas micromag fit",
        "skygas calibrate",
        "skygas infer",
        "skygas optimize",
        "skygas track",
    }
    assert set(with_json) == expected
    helps = {_options(COMMANDS[name])["--json"].help for name in with_json}
    assert all(f"as one JSON object on stdout (indented by {INDENT} spaces" in h for h in helps)
    sample = folder() / "disk-tilted-edges.ovf"
    assert main(["micromag", "inspect", str(sample), "--json"]) == 0
    out = capsys.readouterr().out
    assert out == json_text(json.loads(out)) + "\n"
    assert out.startswith("{\n" + " " * INDENT + '"')


def test_the_run_commands_share_their_flags_and_the_one_checkpoint_default():
    runs = {
        name: _options(p) for name, p in COMMANDS.items() if "--checkpoint-seconds" in _options(p)
    }
    assert set(runs) == {
        "skygas simulate",
        "skygas demo",
        "skygas reshuffle",
        "skygas neuron",
        "skygas saturation",
        "skygas reservoir",
        "skygas calibrate",
    }
    for name, options in runs.items():
        assert options["--checkpoint-seconds"].default == CHECKPOINT_SECONDS, name
        for flag in ("--out", "--resume", "--overwrite", "--strict", "--quiet", "--force"):
            assert flag in options, (name, flag)
    for name, parser in COMMANDS.items():  # the same names mean the same things everywhere
        options = _options(parser)
        if "--seed" in options:
            assert options["--seed"].type is int, name
        if "--duration" in options:
            assert options["--duration"].type is float, name
            assert "[s]" in options["--duration"].help, name


def test_demo_is_the_reshuffler_with_its_defaults_and_make_demo_runs_it():
    parser = build_parser()
    demo = vars(parser.parse_args(["demo"]))
    reshuffle = vars(parser.parse_args(["reshuffle", "--out", "demo-output"]))
    assert demo.pop("command") == "demo" and reshuffle.pop("command") == "reshuffle"
    assert demo == reshuffle  # the same handler, no configuration, no override
    makefile = (ROOT / "Makefile").read_text()
    recipe = re.search(r"^demo:.*\n\t(.*)$", makefile, re.MULTILINE)
    assert recipe is not None
    assert recipe.group(1).split()[1:3] == ["demo", "--out"]


def test_micromag_samples_path_prints_only_the_folder(capsys):
    assert main(["micromag", "samples", "--path"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1
    folder = Path(out.strip())
    assert (folder / "disk-tilted-edges.ovf").is_file() and (folder / "pair").is_dir()
    assert main(["micromag", "samples"]) == 0
    assert str(folder) in capsys.readouterr().out  # without --path: the folder and how to try it


def _tour_command_lines() -> list[str]:
    """The ``skygas ...`` lines of the README's code blocks (its tour)."""
    lines = []
    for page in [ROOT / "README.md"]:
        for block in re.findall(r"^```\n(.*?)^```", page.read_text(), re.DOTALL | re.MULTILINE):
            block = block.replace("\\\n", " ")  # a command continued on the next line
            for line in block.splitlines():
                line = line.split("  #")[0].strip()
                if line.startswith("skygas ") and "[" not in line and "..." not in line:
                    lines.append(line)
    return lines


@pytest.mark.parametrize("line", _tour_command_lines())
def test_the_documented_command_lines_parse(line):
    words = shlex.split(line.replace("$SAMPLES", "samples"))[1:]
    build_parser().parse_args(words)  # argparse exits (SystemExit) on an unknown option


def test_simulate_takes_seed_and_duration_as_the_device_commands_do(tmp_path, capsys):
    config = ROOT / "examples" / "closed-chamber.toml"
    argv = ["simulate", str(config), "--seed", "5", "--duration", "3e-9", "--json", "--no-report"]
    assert main([*argv, "--out", str(tmp_path / "run")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["seed"] == 5
    assert summary["simulated_time_s"] == pytest.approx(3e-9)
