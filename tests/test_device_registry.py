"""The device registry (:mod:`skygas.devices.registry`): names, detection, lazy parts."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from skygas.core.errors import InputError
from skygas.devices.registry import KINDS, kind, kind_of_summary, recorded_kind


def test_an_unknown_kind_is_one_line_naming_the_known_ones():
    with pytest.raises(InputError) as err:
        kind("reshufle")
    text = str(err.value)
    assert "\n" not in text
    assert all(name in text for name in KINDS)


def test_each_summary_key_and_result_file_tells_one_kind_only():
    keys = [key for k in KINDS.values() for key in k.summary_keys]
    files = [name for k in KINDS.values() for name in k.result_files]
    assert len(keys) == len(set(keys)) and len(files) == len(set(files))


def test_a_folder_is_told_by_its_manifest_then_its_file_then_its_keys(tmp_path):
    for device in KINDS.values():
        for key in device.summary_keys:
            assert kind_of_summary({key: 1}, tmp_path) == device.name
        for name in device.result_files:
            assert kind_of_summary({}, tmp_path, name) == device.name
    assert kind_of_summary({"other": 1}, tmp_path) is None
    (tmp_path / "manifest.json").write_text(json.dumps({"command": "sc demo"}))
    assert kind_of_summary({"lif_fit": {}}, tmp_path) == "sc demo"


def test_a_run_of_an_unknown_command_is_reported_as_a_simulation():
    assert recorded_kind("demo").run_headline is not None
    assert recorded_kind("demo") is recorded_kind(next(k for k in KINDS if KINDS[k].uniform_drive))


def test_every_lazy_part_imports():
    for device in KINDS.values():
        if device.config_model is not None:
            assert hasattr(device.config_model(), "model_validate_json")
        if device.occupancy_groups is not None:
            group_of, names = device.occupancy_groups()
            assert len(names) >= 2
        if device.folder_headline is not None:
            device.folder_headline({}, __import__("pathlib").Path("."))


def test_importing_the_registry_imports_no_device():
    code = (
        "import sys, skygas.devices.registry\n"
        "heavy = [m for m in sys.modules if m.split('.')[-1] in "
        "('device', 'run', 'config', 'study')]\n"
        "print(heavy)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout
