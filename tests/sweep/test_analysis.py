"""Scaling fits recover the exponents of exact data; the figures are drawn from a store."""

from __future__ import annotations

import json

import numpy as np
import pytest

from skygas.cli import main
from skygas.sweep import (
    fit_chamber_scaling,
    fit_current_scaling,
    open_sweep,
    parse_sweep,
    plot_sweep,
    running_mean,
)
from skygas.sweep.analysis import power_law_exponent
from skygas.sweep.store import SweepStore
from skygas.sweep.worker import QUANTITIES


def fake_store(path, grid, rho_of):
    """A store filled with ρ = rho_of(config) ± 0.01 (the two replicas average to it exactly)."""
    sweep = parse_sweep(
        {
            "sweep": {"seed": 1, "replicas": 2},
            "base": {"preset": "paper", "duration": 1e-6},
            "grid": grid,
        }
    )
    store = SweepStore(path, sweep)
    for run in sweep.runs:
        result = {q: 0.0 for q in QUANTITIES}
        result["correlation"] = rho_of(run.config) + (0.01 if run.replica == 0 else -0.01)
        t = np.linspace(1e-7, 1e-6, 30)
        result["running_time"] = t
        result["running_rho"] = result["correlation"] + np.exp(-t / 2e-7)
        store.write(run, result, session=0)
    return path


def table_rows(path):
    """The lines of a CSV file without its leading ``# key: value`` provenance block."""
    return [line for line in path.read_text().splitlines() if not line.startswith("#")]


def test_current_fit_recovers_three_halves(tmp_path):
    # ρ = 1/(1 + x^(-3/2)), x = J/1e11, is the paper's law with c_A = c_B = 1 and has
    # ρ/(1 − ρ) = x^(3/2) exactly
    grid = {"current_density": [1e11, 1.5e11, 2e11, 2.7e11, 3.8e11], "signal.p": [0.3, 0.62]}
    path = fake_store(
        tmp_path / "j.zarr", grid, lambda c: 1 / (1 + (c.current_density / 1e11) ** -1.5)
    )
    ds = open_sweep(path)
    fits = fit_current_scaling(ds)
    assert fits["beta"]["exponent"] == pytest.approx(1.5, abs=1e-9)
    assert fits["per_p"]["0.62"]["beta"]["exponent"] == pytest.approx(1.5, abs=1e-9)
    assert fits["paper_fit"]["c_A"] == pytest.approx(1.0, rel=1e-6)
    assert fits["paper_fit"]["c_B"] == pytest.approx(1.0, rel=1e-6)
    curve = running_mean(ds, {"current_density": 2e11, "signal_p": 0.62})
    assert curve["sem"].values == pytest.approx(np.full(200, 0.01 * np.sqrt(2) / np.sqrt(2)))
    result = plot_sweep(path, tmp_path / "figs")
    assert (tmp_path / "figs" / "reshuffler.png").stat().st_size > 10_000
    assert json.loads((tmp_path / "figs" / "fits.json").read_text())["current"]["beta"][
        "exponent"
    ] == pytest.approx(1.5)
    assert result["figures"] == [
        str(tmp_path / "figs" / name) for name in ("reshuffler.png", "reshuffler_details.png")
    ]
    # one row per point, ρ the replica mean of the two replicas (±0.01 around the law)
    rows = table_rows(tmp_path / "figs" / "points.csv")
    assert len(rows) == 1 + 5 * 2
    header = rows[0].split(",")
    first = dict(zip(header, rows[1].split(","), strict=True))
    assert float(first["rho"]) == pytest.approx(
        1 / (1 + (float(first["current_density"]) / 1e11) ** -1.5), rel=1e-5
    )
    assert float(first["rho_sem"]) == pytest.approx(0.01, rel=1e-5)


def test_chamber_fit_and_plot_command(tmp_path, capsys):
    lengths = [4e-7, 6e-7, 8e-7, 1.024e-6, 1.5e-6]
    path = fake_store(
        tmp_path / "l.zarr",
        {"device.chamber_diameter": lengths},
        lambda c: 0.1 + 0.2 / np.sqrt(c.device.chamber_diameter / 1e-6),
    )
    fits = fit_chamber_scaling(open_sweep(path))
    assert fits["paper_fit"]["c_A"] == pytest.approx(0.1, abs=1e-9)
    assert fits["paper_fit"]["c_B"] == pytest.approx(0.2, abs=1e-9)
    assert main(["plot", str(path), "--out", str(tmp_path / "figs")]) == 0
    assert "γ =" in capsys.readouterr().out
    assert (tmp_path / "figs" / "chamber_size.png").exists()


def test_free_exponent_of_exact_power_law():
    length = np.array([0.4, 0.6, 1.0, 1.5, 2.0])
    odds = 0.5 * length**-0.5
    rho = odds / (1 + odds)
    fit = power_law_exponent(length, rho, np.full(5, 0.01))
    assert fit["exponent"] == pytest.approx(-0.5, abs=1e-9) and fit["n_points"] == 5


def test_stores_over_different_points_are_fitted_together(tmp_path, capsys):
    # one grid at p = 0.62, a second at other p-values and some of the same currents: the
    # combined fit sees all 2 × 3 + 2 × 2 points of the exact law ρ/(1 − ρ) = x^(3/2)
    def law(c):
        return 1 / (1 + (c.current_density / 1e11) ** -1.5)

    a = fake_store(
        tmp_path / "a.zarr", {"current_density": [1e11, 1.5e11, 2e11], "signal.p": [0.62]}, law
    )
    b = fake_store(
        tmp_path / "b.zarr", {"current_density": [1.5e11, 3.8e11], "signal.p": [0.3, 0.8]}, law
    )
    from skygas.sweep import open_sweeps

    ds = open_sweeps([a, b])
    assert int(ds["done"].sum()) == 2 * (3 + 4)
    fits = fit_current_scaling(ds)
    assert fits["beta"]["exponent"] == pytest.approx(1.5, abs=1e-9)
    assert fits["beta"]["n_points"] == 7
    assert main(["plot", str(a), str(b), "--out", str(tmp_path / "figs")]) == 0
    rows = table_rows(tmp_path / "figs" / "points.csv")
    assert len(rows) == 1 + 7  # the points no store holds are left out
    capsys.readouterr()
    # a point done in both stores, or stores over different fields: one line, nothing drawn
    c = fake_store(tmp_path / "c.zarr", {"current_density": [2e11], "signal.p": [0.62]}, law)
    d = fake_store(tmp_path / "d.zarr", {"device.chamber_diameter": [4e-7, 8e-7]}, lambda c: 0.1)
    for pair, expected in (
        ((a, c), "current_density = 2e+11, signal_p = 0.62 is done in"),
        ((a, d), "a sweep over the same fields"),
    ):
        assert main(["plot", *map(str, pair), "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err
        assert expected in err and len(err.strip().splitlines()) == 1
        assert not (tmp_path / "bad").exists()


def test_plot_outputs_record_the_store_seed_version_and_fingerprint(tmp_path):
    from PIL import Image

    path = fake_store(
        tmp_path / "j.zarr",
        {"current_density": [1e11, 2e11, 3e11], "signal.p": [0.62]},
        lambda c: 1 / (1 + (c.current_density / 1e11) ** -1.5),
    )
    ds = open_sweep(path)
    out = tmp_path / "figs"
    assert main(["plot", str(path), "--out", str(out)]) == 0
    expected = {
        "skygas_version": ds.attrs["skygas_version"],
        "seed": "1",
        "config_hash": ds.attrs["fingerprint"],
    }
    fits = json.loads((out / "fits.json").read_text())["provenance"]
    assert {k: fits[k] for k in expected} == expected
    assert fits["command"] == "plot" and fits["command_line"].startswith("skygas plot ")
    with Image.open(out / "reshuffler.png") as png:
        assert {k: png.text[k] for k in expected} == expected
        assert png.text["command_line"] == fits["command_line"]
    comments = [
        line[2:].split(": ", 1)
        for line in (out / "points.csv").read_text().splitlines()
        if line.startswith("# ")
    ]
    assert {k: v for k, v in comments if k in expected} == expected
    assert not [p.name for p in out.iterdir() if ".partial" in p.name]
    # a store's report goes beside it (nothing is written into a store), refreshed each time
    for _ in range(2):
        assert main(["report", str(path)]) == 0
    assert (tmp_path / "j-report.html").exists() and not (path / "report.html").exists()
