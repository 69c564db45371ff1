"""The Skyrmion Reshuffler end to end: ordering, decorrelation, p-values, conservation, the
occupied-site rule, bad input, resume and the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.reshuffler import ReshufflerRun, parse_reshuffler_config, summarize
from skygas.reshuffler import correlation as corr

FAST = {
    "spin_drift_coefficient": 1.83e-10,
    "current_density": 3.8e11,
    "output": {"trajectory_window": 0.0, "snapshot_interval": 200e-9},
}


def run_config(**fields) -> tuple[ReshufflerRun, dict]:
    config = parse_reshuffler_config({**FAST, **fields})
    run = ReshufflerRun.build(config)
    run.advance()
    return run, summarize(run).summary


def test_zero_temperature_output_repeats_the_input():
    """Without noise every skyrmion follows the same current line from the same site, so the
    read-out order is the injection order: ρ = 1 and the output bits equal the input bits."""
    run, s = run_config(
        temperature=0.0,
        duration=1e-6,
        spin_drift_coefficient=1e-9,
        signal={"kind": "bernoulli", "p": 0.5},
    )
    det = run.detections()
    bits = run.injector.log.bit
    assert s["n_detected"] > 150
    assert np.array_equal(det["up"], bits[: len(det["up"])])
    assert s["correlation"] == pytest.approx(1.0, abs=1e-12)
    assert s["correlation_best_lag"] == 0


def test_room_temperature_at_lower_current_decorrelates():
    """At 300 K and 1.7e11 A/m² (with the paper preset's ξ) skyrmions spend ~300 ns diffusing
    and overtake each other: ρ falls well below 0.1 (2000 events: standard error ≈ 0.022)."""
    run, s = run_config(current_density=1.7e11, duration=10e-6, seed=3)
    assert s["n_detected"] > 1500
    assert abs(s["correlation"]) < 0.1
    # the same device at high current stays strongly correlated (paper: 0.64 at 3.8e11)
    _, fast = run_config(current_density=3.8e11, duration=5e-6, seed=3)
    assert fast["correlation"] > 0.4


@pytest.mark.parametrize("p", [0.1, 0.5, 0.9])
def test_output_p_value_matches_the_input(p):
    run, s = run_config(duration=4e-6, seed=11, signal={"kind": "bernoulli", "p": p})
    det = run.detections()
    compare = corr.p_out_vs_p_in(run.injector.log.bit, det["up"], confidence=0.99)
    assert compare.p_in_within_output_interval, (s["p_in"], s["p_out"], s["p_out_interval"])
    assert abs(s["p_out"] - p) < 4 * np.sqrt(p * (1 - p) / s["n_detected"])


def test_counts_are_conserved_and_the_occupied_site_rule_is_followed():
    """A weak current leaves each new skyrmion near the site for longer than an injection
    interval, so later nucleations find the site occupied."""
    slow = {"current_density": 2e10, "duration": 0.5e-6, "signal": {"kind": "bernoulli", "p": 0.5}}
    run, s = run_config(**slow, injection={"occupied_rule": "delay", "max_pending": 5})
    log = run.injector.log
    assert s["n_injected"] == s["n_detected"] + s["n_present"] + s["n_annihilated"]
    assert s["n_delayed"] > 0 and s["n_skipped"] > 0  # the queue of 5 overflowed
    # every event is injected, waiting or dropped; none twice
    assert s["n_injected"] + s["n_pending"] + s["n_skipped"] == s["n_events"]
    injected = log.skyrmion >= 0
    ticks = np.arange(len(log.bit)) * run.injector.interval_steps
    assert np.all(log.injection_step[injected] >= ticks[injected])
    on_time = injected & ~log.delayed
    assert np.all(log.injection_step[on_time] == ticks[on_time])
    assert np.all(log.injection_step[log.delayed & injected] > ticks[log.delayed & injected])

    run, s = run_config(**slow, injection={"occupied_rule": "skip"})
    assert s["n_skipped"] > 0 and s["n_delayed"] == 0 and s["n_pending"] == 0
    assert s["n_injected"] + s["n_skipped"] == s["n_events"]
    assert s["n_injected"] == s["n_detected"] + s["n_present"]


def test_nucleation_never_lands_on_another_skyrmion():
    config = parse_reshuffler_config({**FAST, "current_density": 2e10, "duration": 0.3e-6})
    run = ReshufflerRun.build(config)
    clearance = run.injector.clearance_nm
    seen = []
    original = run.injector._nucleate

    def checked(sim, chamber, k):
        site = run.injector.sites[chamber]
        store = sim.state.arrays_nm()
        alive = store.alive
        d = np.hypot(store.x[alive] - site[0], store.y[alive] - site[1])
        seen.append(d.min() if len(d) else np.inf)
        original(sim, chamber, k)

    run.injector._nucleate = checked
    run.advance()
    assert len(seen) > 20 and min(seen) >= clearance


@pytest.mark.parametrize(
    "fields, field",
    [
        ({"device": {"chamber_diameter": 30e-9}}, "chamber_diameter"),
        ({"device": {"conduit_width": 2e-6}}, "conduit_width"),
        ({"time_step": 3e-11}, "time_step"),
        ({"signal": {"p": 1.5}}, "signal.p"),
        ({"temperature": -1.0}, "temperature"),
    ],
)
def test_bad_input_is_refused_before_running(fields, field):
    with pytest.raises(InputError) as err:
        ReshufflerRun.build(parse_reshuffler_config({**FAST, "duration": 1e-7, **fields}))
    assert field in err.value.field


def test_bad_signal_files_are_refused(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("0,1,2,1\n")
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    for path in (bad, empty):
        config = parse_reshuffler_config(
            {**FAST, "duration": 1e-7, "signal": {"kind": "file", "path": str(path)}}
        )
        with pytest.raises(InputError):
            ReshufflerRun.build(config)


def test_a_file_signal_drives_the_injections(tmp_path):
    bits = np.array([1, 1, 0, 1, 0, 0, 0, 1] * 10, dtype=np.int8)
    path = tmp_path / "bits.npy"
    np.save(path, bits)
    run, s = run_config(duration=0.4e-6, signal={"kind": "file", "path": str(path)})
    assert np.array_equal(run.injector.log.bit, bits.astype(bool))
    assert s["n_events"] == 80


def test_resume_from_a_checkpoint_is_bit_identical():
    """Checkpoints are taken between pieces of a run (here the first of two)."""
    from skygas.reshuffler.run import MIN_PIECE_STEPS

    config = parse_reshuffler_config({**FAST, "duration": 1.6e-6, "seed": 5})
    straight = ReshufflerRun.build(config)
    straight.advance(pieces=2)
    first = ReshufflerRun.build(config)
    assert first.total_steps > MIN_PIECE_STEPS
    first.advance(pieces=2, stop_after_step=MIN_PIECE_STEPS)
    state = first.state_dict()
    second = ReshufflerRun.build(config)
    second.load_state_dict(state)
    second.advance(pieces=2)
    a, b = straight.detections(), second.detections()
    assert len(a["time"]) > 50
    for key in a:
        assert np.array_equal(a[key], b[key])
    assert np.array_equal(straight.sim.positions()[1], second.sim.positions()[1])


def test_cli_json_summary_has_the_documented_fields(tmp_path, capsys):
    code = main(
        [
            "reshuffle",
            "--out",
            str(tmp_path),
            "--json",
            "--duration",
            "3e-7",
            "--current-density",
            "3.8e11",
            "--spin-drift-coefficient",
            "1.83e-10",
            "--p",
            "0.3",
            "--seed",
            "2",
            "--temperature",
            "300",
        ]
    )
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    for key in [
        "correlation",
        "correlation_max_lag",
        "scc",
        "p_in",
        "p_out",
        "n_injected",
        "n_detected",
        "n_skipped",
        "n_present",
        "max_occupancy",
        "mean_transit_s",
        "current_density_A_m2",
        "chamber_diameter_m",
        "temperature_K",
        "power_W",
        "energy_per_bit_J",
        "simulated_time_s",
        "time_step_s",
        "wall_time_s",
    ]:
        assert key in summary
    assert summary["current_density_A_m2"] == 3.8e11
    for name in [
        "reshuffler.nc",
        "summary.json",
        "device.png",
        "running_correlation.png",
        "occupancy.png",
    ]:
        assert (tmp_path / name).exists()
    import xarray as xr

    ds = xr.open_dataset(tmp_path / "reshuffler.nc")
    assert json.loads(ds.attrs["config_json"])["signal"]["p"] == 0.3
    assert ds.attrs["seed"] == 2 and "skygas_version" in ds.attrs
    assert int(ds.detection_up.size) == summary["n_detected"]


@pytest.mark.parametrize("rule", ["delay", "skip"])
def test_nucleations_made_in_the_kernel_follow_the_python_rule_exactly(rule):
    """The injector hands its nucleations to the compiled kernel while no queue is waiting
    (skygas.engine.PlannedInsertions). At T = 0 with sites often occupied, a run must log the
    same nucleation for every event as a run that returns to Python at every tick, and end
    with the same skyrmions at the same places (to rounding: lists are rebuilt at other
    moments, so pair sums are added in another order)."""
    config = parse_reshuffler_config(
        {
            **FAST,
            "temperature": 0.0,
            "current_density": 6e10,
            "duration": 0.4e-6,
            "signal": {"kind": "bernoulli", "p": 0.5},
            "injection": {"occupied_rule": rule, "max_pending": 5},
        }
    )
    planned, python = ReshufflerRun.build(config), ReshufflerRun.build(config)
    python.injector.plan_insertions = lambda step, limit: None
    made_in_kernel = []
    report = planned.injector.planned_insertions_made
    planned.injector.planned_insertions_made = lambda sim, ids: (
        made_in_kernel.extend(ids),
        report(sim, ids),
    )
    planned.advance()
    python.advance()
    a, b = planned.injector.log, python.injector.log
    assert (a.delayed | a.skipped).sum() >= 10  # the rule was exercised (35 / 14 events)
    assert len(made_in_kernel) >= 10  # and so was the kernel (11 / 31 events)
    for name in ("skyrmion", "injection_step", "delayed", "skipped"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    ids_a, pos_a = planned.sim.positions()
    ids_b, pos_b = python.sim.positions()
    assert np.array_equal(ids_a, ids_b)
    assert np.abs(pos_a - pos_b).max() < 1e-15  # metres: 1e-6 nm
    assert planned.sim.step == python.sim.step


def test_snapshots_recorded_in_the_kernel_equal_positions_read_at_each_snapshot_step():
    """The kernel records the snapshots itself (frames with the id in each slot), also while it
    makes planned nucleations and removes read-out skyrmions. They must equal what
    ``Simulation.positions`` returns when the run stops at every snapshot step and returns to
    Python for every nucleation, read before a nucleation due at the same step (T = 0, so the
    runs differ only by rounding: pair sums are added in another order)."""
    from skygas.engine import Periodic

    config = parse_reshuffler_config(
        {
            **FAST,
            "temperature": 0.0,
            "duration": 0.4e-6,
            "output": {"trajectory_window": 50e-9, "snapshot_interval": 20e-9},
        }
    )
    recorded, reference = ReshufflerRun.build(config), ReshufflerRun.build(config)
    reference.injector.plan_insertions = lambda step, limit: None
    read = []
    # first in the list: it reads the positions before a nucleation due at the same step
    reference.sim.operations.insert(
        0, Periodic(reference.snapshot_steps, lambda sim: read.append((sim.time, *sim.positions())))
    )
    recorded.advance()
    reference.advance()
    # the first snapshot is the empty device at t = 0; the operation first acts one interval on
    start, *snaps = recorded.snapshots
    assert start[0] == 0.0 and len(start[1]) == 0 and start[2].shape == (0, 2)
    assert len(snaps) == len(read) == 20
    assert recorded.counts()["detected"] >= 5  # skyrmions left between snapshots
    for (t_a, ids_a, pos_a), (t_b, ids_b, pos_b) in zip(snaps, read, strict=True):
        assert t_a == pytest.approx(t_b, rel=1e-12)
        assert np.array_equal(ids_a, ids_b)
        assert np.abs(pos_a - pos_b).max(initial=0.0) < 1e-15  # metres
    # the figure's dense frames: every 1 ns of the window, on the snapshot steps as well
    ds = recorded.sim.trajectories()
    assert len(ds.time) == 51 and ds.time.values[0] == 0.0  # t = 0 and every 1 ns to 50 ns
    assert np.allclose(np.diff(ds.time.values), 1e-9)
    # one column per skyrmion seen in the window, not per skyrmion ever nucleated
    in_window = np.unique(np.concatenate([ids for t, ids, _ in snaps if t <= 50e-9]))
    assert set(in_window) <= set(ds.skyrmion.values)
    assert ds.sizes["skyrmion"] < recorded.sim.ids_issued
    assert np.isfinite(ds.x.values).any(axis=0).all()
    # and a checkpoint keeps them
    restored = ReshufflerRun.build(config)
    restored.sim.load_state_dict(recorded.sim.state_dict())
    again = restored.sim.trajectories()
    assert np.array_equal(again.skyrmion.values, ds.skyrmion.values)
    assert np.array_equal(again.x.values, ds.x.values, equal_nan=True)


def test_one_long_kernel_call_records_more_exits_than_the_storage_capacity():
    """Without snapshots or checkpoints to stop it, one kernel call nucleates and reads out
    far more skyrmions than the state has slots (64): every exit must be recorded once."""
    config = parse_reshuffler_config(
        {**FAST, "duration": 1e-6, "output": {"trajectory_window": 0.0, "snapshot_interval": 1.0}}
    )
    run = ReshufflerRun.build(config)
    calls = []
    advance = run.sim._advance
    run.sim._advance = lambda *a, **k: (calls.append(1), advance(*a, **k))[1]
    run.advance(pieces=1)
    counts = run.counts()  # raises unless injected = detected + present
    assert counts["detected"] > 2 * run.sim.store.capacity and len(calls) < 10
    assert len(np.unique(run.detections()["skyrmion"])) == counts["detected"]


def test_neighbour_list_edits_at_nucleation_and_read_out_miss_no_pair():
    """A nucleated skyrmion is appended to the engine's neighbour list and a read-out one
    removed from it, without a rebuild. A run whose list is rebuilt exactly before every force
    evaluation (zero margins) must count the same pair forces and end in the same state (to
    rounding: pair sums may be added in another order; a missed pair would move a skyrmion
    by ≳ 1e-3 nm)."""
    runs = []
    for exact in (False, True):
        run = ReshufflerRun.build(
            parse_reshuffler_config(
                {
                    **FAST,
                    "duration": 0.3e-6,
                    "seed": 3,
                    "output": {"trajectory_window": 0.0, "snapshot_interval": 1.0},
                }
            )
        )
        if exact:
            run.sim.neighbor_cells = run.sim.neighbor_cells._replace(
                skin=0.0, margin_steps=0.0, margin_max=0.0
            )
        run.advance()
        runs.append(run)
    edited, exact = runs
    assert edited.counts()["injected"] >= 50 and edited.counts()["detected"] >= 30
    assert edited.sim.neighbor_rebuilds < exact.sim.neighbor_rebuilds / 5
    assert edited.sim.pair_evaluations == exact.sim.pair_evaluations
    ids_a, pos_a = edited.sim.positions()
    ids_b, pos_b = exact.sim.positions()
    assert np.array_equal(ids_a, ids_b)
    assert np.abs(pos_a - pos_b).max() < 1e-16  # metres: 1e-7 nm


def test_a_run_too_short_to_read_out_shows_no_nan(tmp_path, capsys):
    """Before any skyrmion is read out there is no correlation and no transit time: the
    summary says so instead of printing nan."""
    from skygas.cli import main

    out = tmp_path / "short"
    assert (
        main(["reshuffle", "--duration", "5e-8", "--out", str(out), "--quiet", "--no-report"]) == 0
    )
    text = capsys.readouterr().out
    assert "nan" not in text.lower()
    assert "correlation: none yet (0 skyrmion(s) read out" in text
    assert "no transit completed yet" in text
