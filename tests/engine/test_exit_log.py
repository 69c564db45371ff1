"""The exit log: batches in, the same exits out as arrays, tuples and after a save/restore."""

import numpy as np
import pytest

from skygas.engine.exit_log import ExitLog


def test_batches_read_back_as_arrays_and_tuples_in_order():
    log = ExitLog(["in", "out"])
    assert len(log) == 0 and list(log) == [] and len(log.arrays()["time"]) == 0
    log.append([4, 7], [1e-9, 2e-9], [1, 0], [1e-7, 2e-7], [3e-7, 4e-7])
    log.append([], [], [], [], [])  # an empty batch changes nothing
    log.append([9], [3e-9], [1], [5e-7], [6e-7])
    a = log.arrays()
    assert a["skyrmion"].tolist() == [4, 7, 9]
    assert a["time"].tolist() == [1e-9, 2e-9, 3e-9]
    assert log.port_labels().tolist() == ["out", "in", "out"]
    assert list(log) == [
        (4, 1e-9, "out", 1e-7, 3e-7),
        (7, 2e-9, "in", 2e-7, 4e-7),
        (9, 3e-9, "out", 5e-7, 6e-7),
    ]
    assert log[1] == (7, 2e-9, "in", 2e-7, 4e-7)
    with pytest.raises(ValueError):
        a["time"][0] = 0.0  # the merged columns are read-only


def test_a_batch_is_copied_so_reused_buffers_do_not_change_the_log():
    log = ExitLog(["out"])
    ids = np.array([1, 2])
    log.append(ids, [0.0, 1.0], [0, 0], [0.0, 0.0], [0.0, 0.0])
    ids[:] = 99
    assert log.arrays()["skyrmion"].tolist() == [1, 2]


def test_rebuilt_from_saved_columns():
    log = ExitLog(["a", "b"])
    log.append([3, 5], [1.0, 2.0], [1, 0], [0.1, 0.2], [0.3, 0.4])
    back = ExitLog.from_arrays(
        ["a", "b"],
        log.arrays()["skyrmion"],
        log.arrays()["time"],
        log.port_labels(),
        log.arrays()["x"],
        log.arrays()["y"],
    )
    assert list(back) == list(log)
