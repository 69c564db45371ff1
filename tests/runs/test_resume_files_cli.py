"""A run killed at any file of its final write, and a second run into a folder in use.

Apart from test_resume_cli.py, whose module-scoped reference runs these tests do not use: in a
module of their own they can run on the other test worker meanwhile.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import signal

from skygas.cli import main

from .test_resume_cli import (
    SIMULATE_TOML,
    _argv,
    _cli,
    _Started,
    assert_same_results,
)


def _forked(argv: list[str], kill_at_rename: int = 0) -> int:
    """``skygas argv`` in a child forked from this process (the package and the engine's
    kernels already loaded: a fraction of a second, where a new interpreter takes seconds);
    its exit status, negative for the signal that ended it.

    With ``kill_at_rename = n``, the child kills itself (SIGKILL: no chance to clean up) just
    before the n-th rename of a finished temporary file into place, wherever it comes: the
    manifest, a checkpoint, a result file, the report.
    """
    child = multiprocessing.get_context("fork").Process(
        target=_run_and_exit, args=(argv, kill_at_rename)
    )
    child.start()
    child.join(300)
    assert child.exitcode is not None, "the child did not finish in 300 s"
    return child.exitcode


def _run_and_exit(argv: list[str], kill_at_rename: int) -> None:
    if kill_at_rename:
        calls, original = [0], os.replace

        def replace(*args, **kwargs):
            calls[0] += 1
            if calls[0] == kill_at_rename:
                os.kill(os.getpid(), signal.SIGKILL)
            return original(*args, **kwargs)

        os.replace = replace  # type: ignore[assignment]
    os._exit(main(argv))  # no test-session clean-up in the child


SHORT_TOML = SIMULATE_TOML.replace("duration = 30e-6", "duration = 2e-6")


def test_a_kill_at_any_file_of_the_final_write_is_completed_by_resume(tmp_path):
    """Killed before each rename of a run, one after the other (the manifest at the start,
    the final checkpoint, every result file, the report, the finished manifest), the run
    always leaves a folder that ``--resume`` completes into the results of a run left alone,
    with no temporary file behind."""
    config = tmp_path / "short.toml"
    config.write_text(SHORT_TOML)
    ref = tmp_path / "ref"
    # in this process: the children forked from it find the engine's kernels loaded
    assert main(["simulate", str(config), "--out", str(ref), "--quiet"]) == 0
    files = ("trajectories.nc", "summary.json")
    killed = 0
    for nth in range(1, 30):
        out = tmp_path / f"out{nth}"
        argv = ["simulate", str(config), "--out", str(out), "--quiet"]
        code = _forked(argv, kill_at_rename=nth)
        if code == 0:  # fewer renames than nth: every kill point has been tried
            break
        assert code == -signal.SIGKILL, (nth, code)
        killed += 1
        assert _forked([*argv, "--resume"]) == 0, nth
        assert_same_results(ref, out, files)
        assert (out / "report.html").is_file()
        assert json.loads((out / "manifest.json").read_text())["finished_at"] is not None
        leftovers = [p.name for p in out.iterdir() if "partial" in p.name or p.name.startswith(".")]
        assert leftovers == [], (nth, leftovers)
    assert killed >= 6  # the manifest twice, the checkpoint, three result files, the report


def test_a_second_run_into_a_folder_in_use_is_refused_at_once(tmp_path):
    """Two runs into one folder: the second is refused with one line naming the first
    (command, process), and the first finishes untouched. A lock left by a killed run is
    taken over without a word."""
    out = tmp_path / "out"
    argv = _argv("simulate", tmp_path, out)
    first = _Started(argv)
    assert first.bar.wait(120), first.stderr.decode()
    second = _cli([*_argv("simulate", tmp_path, out), "--quiet"])
    assert second.returncode == 2, second.stderr
    line = second.stderr.strip().splitlines()
    assert len(line) == 1 and "is writing into it" in line[0], second.stderr
    assert f"process {first.proc.pid}" in line[0] and "skygas simulate" in line[0]
    assert first.proc.wait(300) == 0, first.stderr.decode()
    assert (out / "summary.json").is_file() and not (out / ".skygas.lock").exists()

    # a run killed while it holds the folder: its lock dies with it
    killed = _Started([*argv, "--overwrite"])
    assert killed.stop(signal.SIGKILL, 0.2) == -signal.SIGKILL
    again = _cli([*argv, "--overwrite", "--quiet"])
    assert again.returncode == 0, again.stderr
