"""``Simulation.plot`` and ``skygas.plot``: figures of the state and of recorded trajectories."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.collections import EllipseCollection
from matplotlib.figure import Figure

import skygas
from skygas.core.errors import InputError


def _wall_lines_um(ax) -> list[np.ndarray]:
    return [np.column_stack(line.get_data()) for line in ax.lines if line.get_color() == "black"]


@pytest.fixture(scope="module")
def sim():
    outline = skygas.chamber_with_conduits(chamber_diameter=600e-9)
    sim = skygas.Simulation(outline, "S2", temperature=300.0, seed=3, step_interval=1e-9)
    sim.add_random(5)
    sim.run(4e-9, record_interval=1e-9)
    return sim


def _outline_drawn(ax, outline) -> None:
    walls = _wall_lines_um(ax)
    assert walls, "no wall drawn"
    drawn = np.vstack(walls)
    x0, y0, x1, y1 = outline.bounds
    # the walls span the outline's bounding box (µm)
    assert drawn[:, 0].min() == pytest.approx(x0 * 1e6, abs=1e-9)
    assert drawn[:, 0].max() == pytest.approx(x1 * 1e6, abs=1e-9)
    assert drawn[:, 1].min() == pytest.approx(y0 * 1e6, abs=1e-9)
    assert drawn[:, 1].max() == pytest.approx(y1 * 1e6, abs=1e-9)


def test_simulation_plot_draws_the_outline_and_each_skyrmion(sim):
    fig = sim.plot()
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    _outline_drawn(ax, sim.outline)
    (discs,) = [c for c in ax.collections if isinstance(c, EllipseCollection)]
    _, positions = sim.positions()
    np.testing.assert_allclose(discs.get_offsets(), positions * 1e6)
    assert "5 skyrmions" in ax.get_title()


def test_simulation_plot_draws_on_given_axes(sim):
    fig = Figure()
    ax = fig.add_subplot()
    assert sim.plot(ax=ax) is fig
    _outline_drawn(ax, sim.outline)


def test_skygas_plot_draws_each_track_over_the_outline(sim):
    ds = sim.trajectories()
    fig = skygas.plot(ds)
    ax = fig.axes[0]
    _outline_drawn(ax, sim.outline)
    tracks = [
        line for line in ax.lines if line.get_linestyle() == "-" and line.get_color() != "black"
    ]
    tracks = [t for t in tracks if len(t.get_xdata()) == len(ds.time)]
    assert len(tracks) == 5
    np.testing.assert_allclose(tracks[0].get_xdata(), ds.x.values[:, 0] * 1e6)


def test_skygas_plot_reads_a_saved_file(sim, tmp_path):
    import xarray as xr

    path = tmp_path / "trajectories.nc"
    sim.trajectories().to_netcdf(path)
    with xr.open_dataset(path) as ds:
        fig = skygas.plot(ds)
    _outline_drawn(fig.axes[0], sim.outline)


def test_skygas_plot_refuses_what_is_not_a_trajectories_dataset():
    import xarray as xr

    with pytest.raises(InputError) as err:
        skygas.plot(xr.Dataset())
    assert err.value.field == "dataset"
    with pytest.raises(InputError):
        skygas.plot(xr.Dataset({"x": ("t", [0.0]), "y": ("t", [0.0])}))  # no outline
