"""Every device's figures can be read: no text over another text, outside the figure or over
another panel, no inset or legend over data, no labelled line off its axis, no colour image
without its colour bar (:func:`~tests.outputs.figure_layout.layout_faults`).

The figures come from the shortest runs (simulate, reshuffler, neuron, sc demo, sc reshuffler)
or from small inputs to the figure functions (reservoir, sweep, micromag fit, neuron transfer
and saturation). The calibration's figures need magnum.np and minutes: not drawn here.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

from .figure_layout import layout_faults


@pytest.fixture
def faults(monkeypatch):
    """The layout faults of every figure saved while the test runs, by file name."""
    found: dict[str, list[str]] = {}
    save = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        # write_figure saves to ".NAME.partial.png" first: the name is NAME.png
        name = Path(str(fname)).name.lstrip(".").replace(".partial", "")
        found[name] = layout_faults(self)
        return save(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return found


def _none(found: dict[str, list[str]], names) -> None:
    assert set(names) <= set(found), sorted(found)
    assert {name: f for name, f in found.items() if f} == {}


def test_the_check_finds_each_fault():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    clean = Figure(figsize=(4, 3))
    ax = clean.add_subplot()
    ax.plot([0, 1], [0, 1], label="data")
    ax.set_xlabel("x (m)")
    ax.legend()
    clean.tight_layout()
    assert layout_faults(clean) == []
    bad = Figure(figsize=(8, 3))
    FigureCanvasAgg(bad)
    ax, pictured = bad.subplots(1, 2)
    ax.plot(np.linspace(0, 1, 50), np.linspace(0, 1, 50))
    ax.text(0.1, 0.8, "one label")
    ax.text(0.12, 0.8, "another label")  # on the first
    ax.text(0.5, 1.4, "far above")  # above the figure
    ax.axhline(5.0, label="reference")  # the axis ends at 1
    ax.set_ylim(0, 1)
    inset = ax.inset_axes((0.3, 0.3, 0.4, 0.4))  # over the diagonal line
    inset.plot([0, 1], [1, 0])
    pictured.imshow(np.arange(4.0).reshape(2, 2))  # no colour bar
    text = " ".join(layout_faults(bad))
    for fault in (
        "texts 'one label' and 'another label' overlap",
        "'far above' reaches outside the figure",
        "the line 'reference' lies outside its panel",
        "an image has no colour bar",
        "an inset covers",
        "points of its panel's data",
    ):
        assert fault in text, text


def test_simulation_figure(faults, tmp_path):
    from skygas.runs.config import parse_config
    from skygas.runs.runner import run_simulation

    config = {
        "seed": 7,
        "duration": 5e-9,
        "record_interval": 1e-9,
        "geometry": {"kind": "shapes", "shapes": [{"kind": "disk", "diameter": 300e-9}]},
        "skyrmions": {"positions": [[0.0, 0.0], [70e-9, 0.0]]},
        "potentials": [
            {"kind": "gaussian", "center": [0.0, 0.0], "sigma": 40e-9, "amplitude_kT": 6.0}
        ],
    }
    run_simulation(parse_config(config), tmp_path, progress=False)
    _none(faults, ["trajectories.png"])


def test_reshuffler_figures(faults, tmp_path):
    from skygas.reshuffler.config import load_reshuffler_config
    from skygas.reshuffler.files import run_reshuffler

    config = load_reshuffler_config(
        overrides={"duration": 0.05e-6, "output.snapshot_interval": 4e-9}
    )
    run_reshuffler(config, tmp_path, progress=False)
    _none(faults, ["device.png", "running_correlation.png", "occupancy.png"])


def test_neuron_figures(faults, tmp_path):
    from skygas.neuron import NeuronDevice, neuron_config
    from skygas.neuron.figures import plot_device, plot_saturation, plot_trace, plot_transfer

    run = NeuronDevice(neuron_config({})).build(duration=100e-9).run(record_interval=2e-9)
    plot_device(run, tmp_path / "device.png")
    plot_trace(run, tmp_path / "count_trace.png")
    rates = [2e6, 5e6, 1e7, 2e7]
    curve = {"input_rate_Hz": rates, "firing_rate_Hz": [0.0, 1e5, 1e6, 4e6]}
    plot_transfer(curve, tmp_path / "transfer_curve.png", {"predicted_Hz": [0, 2e5, 1.1e6, 3.8e6]})
    diameters = np.array([200e-9, 400e-9, 800e-9])
    saturation = SimpleNamespace(
        diameters=diameters,
        max_count=np.array([10.0, 40.0, 150.0]),
        max_count_error=np.array([0.5, 1.0, 2.0]),
        close_packing=np.array([14.0, 58.0, 230.0]),
        parameters={"relax_time_s": 2e-9, "temperature_K": 300.0},
    )
    plot_saturation(saturation, tmp_path / "max_density.png")
    _none(faults, ["device.png", "count_trace.png", "transfer_curve.png", "max_density.png"])


def _scores(accuracy: float, chance: float, n_test: int) -> dict:
    se = float(np.sqrt(chance * (1 - chance) / n_test))
    return {"accuracy": accuracy, "chance": chance, "n_test": n_test, "chance_standard_error": se}


def test_reservoir_figures(faults, tmp_path):
    from skygas.reservoir.config import reservoir_config
    from skygas.reservoir.device import ReservoirDevice
    from skygas.reservoir.figures import plot_accuracies, plot_occupation
    from skygas.reservoir.tasks import BOOLEAN_NAMES, BOOLEAN_ORDER

    device = ReservoirDevice(reservoir_config())
    extent = device.map_extent()
    ny, nx = device.map_shape()
    x = np.linspace(extent[0], extent[1], nx)
    y = np.linspace(extent[2], extent[3], ny)[:, None]
    rng = np.random.default_rng(1)
    maps = [  # a blob of frames pulled a different way by each input
        rng.poisson(200 * np.exp(-((x - 20 * k) ** 2 + (y - 10 * k) ** 2) / 800.0))
        for k in range(len(device.drive.symbols))
    ]
    stream = SimpleNamespace(occupation=np.array(maps, float), map_extent=extent)
    plot_occupation(device, [stream], tmp_path / "occupation.png")
    summary = {
        "hold_time_s": 2e-7,
        "boolean": {
            name: _scores(rng.uniform(0.5, 1.0), 0.5 if k % 3 else 1.0, 40)
            for k, name in enumerate(BOOLEAN_NAMES[n] for n in BOOLEAN_ORDER)
        },
        "temporal": {
            "recall": {str(k): _scores(1.0 - 0.1 * k, 0.55, 32) for k in (1, 2, 3, 4)},
            "parity_last_two": _scores(0.62, 0.5, 32),
        },
    }
    plot_accuracies(summary, tmp_path / "accuracy.png")
    _none(faults, ["occupation.png", "accuracy.png"])


def _sweep_store(path, grid) -> Path:
    """A two-replica store with the paper's ρ(J) and a chamber filling at low currents."""
    from skygas.sweep import parse_sweep
    from skygas.sweep.store import SweepStore
    from skygas.sweep.worker import QUANTITIES

    sweep = parse_sweep(
        {"sweep": {"seed": 1, "replicas": 2}, "base": {"preset": "paper"}, "grid": grid}
    )
    store = SweepStore(path, sweep)
    rng = np.random.default_rng(0)
    for run in sweep.runs:
        x = run.config.current_density / 1e11 * (run.config.device.chamber_diameter / 1e-6)
        result = {q: 0.0 for q in QUANTITIES}
        result["correlation"] = 1 / (1 + x**-1.5) + rng.normal(0, 0.01)
        result["correlation_max_lag"] = result["correlation"] + 0.02
        result["correlation_best_lag"] = float(rng.integers(-2, 3))
        result["p_in"] = run.config.signal.p
        result["p_out"] = run.config.signal.p + rng.normal(0, 0.005)
        result["p_out_low"], result["p_out_high"] = result["p_out"] - 0.02, result["p_out"] + 0.02
        result["max_occupancy"] = float(int(60 / x))
        result["mean_transit_s"] = 2e-7 / x
        t = np.linspace(1e-7, 1e-6, 12)
        result["running_time"] = t
        result["running_rho"] = result["correlation"] + np.exp(-t / 2e-7)
        store.write(run, result, session=0)
    return path


def test_sweep_figures(faults, tmp_path):
    from skygas.sweep import plot_sweep

    grid = {"current_density": [1e10, 1e11, 3.8e11], "signal.p": [0.1, 0.3, 0.5, 0.62, 0.9]}
    plot_sweep(_sweep_store(tmp_path / "j.zarr", grid), tmp_path / "j")
    plot_sweep(
        _sweep_store(tmp_path / "l.zarr", {"device.chamber_diameter": [5e-7, 1e-6, 2e-6]}),
        tmp_path / "l",
    )
    names = ["reshuffler.png", "reshuffler_details.png", "chamber_size.png"]
    _none(faults, [*names, "chamber_size_details.png"])


def test_dodged_series_stand_apart_around_their_point():
    from skygas.sweep.figures import dodge

    x = np.array([1e10, 1e11, 3.8e11])
    shifted = np.array([dodge(x, k, 5, log=True) for k in range(5)])
    assert np.all(np.diff(shifted, axis=0) > 0)  # side by side, in order
    np.testing.assert_allclose(np.exp(np.log(shifted).mean(axis=0)), x)  # centred (log axis)
    assert np.all(shifted[-1, :-1] < shifted[0, 1:])  # each point's group clear of the next
    np.testing.assert_array_equal(dodge(x, 0, 1, log=True), x)  # a single series stays put
    lin = np.array([dodge([1.0, 2.0], k, 3, log=False) for k in range(3)])
    np.testing.assert_allclose(lin.mean(axis=0), [1.0, 2.0])


def test_sc_demo_figures(faults, tmp_path):
    from skygas.sc.demo import run_demo

    run_demo(tmp_path, n_bits=256)
    _none(faults, ["sc_and_squaring.png", "sc_error_vs_length.png", "sc_decorrelators.png"])


def test_sc_reshuffler_figure(faults, tmp_path):
    from skygas.reshuffler.decorrelator import reshuffler_demo

    reshuffler_demo(tmp_path, n_bits=256, trials=1)
    _none(faults, ["sc_reshuffler.png"])


def test_micromag_fit_figure(faults, tmp_path):
    from skygas.micromag.export import plot_fits
    from skygas.micromag.forces import LawFit, pair_law_magnitude
    from skygas.physics.materials import preset

    law = tuple(preset("S2").pair_law)
    d = np.linspace(1.2, 2.3, 30)
    force = 4e-12 * pair_law_magnitude(d, law)
    fit = LawFit("pair", law, (0.1, 0.2, 0.3), 4e-12, d.size, (1.2, 2.3), 0.01)
    plot_fits(tmp_path / "fit.png", {"pair": (d, force)}, {"pair": fit})
    _none(faults, ["fit.png"])
