"""Bad input to ``skygas optimize``: refused in one line before any trial runs.

Each case runs the real command line (:func:`.catalogue.refused`) on a study of the analytic
device (:mod:`skygas.optimize.analytic`; its ``delay`` makes a run as long as wished), or of the
reshuffler where its own configuration refuses a value: exit status 2, one ``skygas: error:``
line naming the field (the study file's key, or the option), nothing written.
"""

from __future__ import annotations

import pytest

from .catalogue import refused

STUDY = """[study]
device = "analytic"
{study}
[base]
delay = {delay}
[space]
{space}
[[objectives]]
expression = "f"
"""
GOOD_SPACE = "x = { low = -1.0, high = 1.0 }"
RESHUFFLER = """[study]
device = "reshuffler"
[base]
duration = 1e-6
[space]
duration = { low = -1e-6, high = 2e-6 }
[[objectives]]
expression = "abs(correlation)"
"""
FILES = {
    "reevaluate.toml": STUDY.format(
        study="reevaluate = 3\nreevaluate_replicas = 1000000000", delay=0.0, space=GOOD_SPACE
    ),
    "candidates.toml": STUDY.format(study="reevaluate = 1000000000", delay=0.0, space=GOOD_SPACE),
    "negative-duration.toml": RESHUFFLER,
    "overflow.toml": STUDY.format(study="", delay=0.0, space="x = { low = -1e308, high = 1e308 }"),
    "outside.toml": STUDY.format(
        study="", delay=0.0, space=f"{GOOD_SPACE}\nnoise = {{ low = -1.0, high = 1.0 }}"
    ),
    "long.toml": STUDY.format(
        study="replicas = 100\nreevaluate = 100\nreevaluate_replicas = 100",
        delay=60.0,
        space=GOOD_SPACE,
    ),
    "good.toml": STUDY.format(study="", delay=0.0, space=GOOD_SPACE),
}
CASES = {
    # a count of a billion grew the client by 50 MB/s, silently
    "a re-evaluation count of a billion": (
        ["reevaluate.toml"],
        "study.reevaluate_replicas = 1000000000",
        "from 1 to 1000",
    ),
    "a billion candidates to re-evaluate": (
        ["candidates.toml"],
        "study.reevaluate = 1000000000",
        "from 0 to 1000",
    ),
    "a range whose width overflows": (["overflow.toml"], "space.x = ", "width high − low"),
    # the reshuffler's own configuration refuses a negative duration: named by the range's end
    "a range end the device refuses": (
        ["negative-duration.toml"],
        "space.duration.low = -1e-06",
        "a number > 0",
    ),
    "a range outside the field's values": (
        ["outside.toml"],
        "space.noise.low = -1.0",
        "a number >= 0",
    ),
    "a study longer than a day": (
        ["long.toml", "--trials", "100"],
        "study = '10000 runs of 100 trials + 10000 re-evaluation runs'",
        "at most 24 h",
        "--force",
    ),
    "no trials": (["good.toml", "--trials", "0"], "--trials = 0", "from 1 to 100000"),
    "trials beyond what a study can hold": (
        ["good.toml", "--trials", "1000000000"],
        "--trials = 1000000000",
        "from 1 to 100000",
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_a_bad_study_is_refused_in_one_line(name, tmp_path):
    args, *expected = CASES[name]
    for file, text in FILES.items():
        (tmp_path / file).write_text(text)
    refused(["optimize", *args, "--out", "out", "--serial"], tmp_path, *expected)
