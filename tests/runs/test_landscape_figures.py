"""Device figures draw the energy landscape under the outline and the trajectories: the shared
helper's image is U/k_BT (checked against a Gaussian bump of known height), and the figures of
``skygas simulate``, the reshuffler and the neuron are written with a landscape."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from skygas.cli import main
from skygas.engine import Simulation
from skygas.figures.plotting import draw_landscape, landscape_energy
from skygas.physics.geometry import disk

BUMP = {"kind": "gaussian", "center": [0.0, 0.0], "sigma": 40e-9, "amplitude_kT": 6.0}


def test_the_landscape_image_is_the_energy_in_kT_inside_the_outline():
    sim = Simulation(disk(diameter=300e-9), "S2", temperature=300.0, landscape=[BUMP])
    u, label = landscape_energy(sim.landscape, sim.outline)
    assert label == "U (k_BT, T = 300 K)"
    assert np.nanmax(u) == pytest.approx(6.0, rel=1e-3)  # the bump's top, 6 k_BT
    gx, gy = sim.landscape.grid.nodes()
    assert np.all(np.isnan(u[np.hypot(gx, gy) > 151.0]))  # nothing drawn outside
    sim.set_landscape_enabled(0, False)  # a switched-off gate is drawn ...
    assert np.nanmax(landscape_energy(sim.landscape, sim.outline)[0]) == pytest.approx(
        6.0, rel=1e-3
    )
    assert sim.landscape.enabled == [False]  # ... and stays off
    fig = Figure()
    ax = fig.add_subplot()
    assert draw_landscape(ax, sim.landscape, sim.outline) is not None
    assert fig.axes[-1].get_ylabel() == label  # the colour bar, with units
    bare = Simulation(disk(diameter=300e-9), "S2", temperature=300.0)
    assert draw_landscape(ax, bare.landscape, bare.outline) is None


def test_simulate_and_reshuffler_figures_with_a_landscape(tmp_path):
    config = tmp_path / "tiny.toml"
    config.write_text(
        "seed = 7\nduration = 5e-9\nrecord_interval = 1e-9\n[geometry]\nkind = 'shapes'\n"
        "shapes = [{ kind = 'disk', diameter = 300e-9 }]\n[skyrmions]\n"
        "positions = [[0.0, 0.0], [70e-9, 0.0]]\n[[potentials]]\nkind = 'gaussian'\n"
        "center = [0.0, 0.0]\nsigma = 40e-9\namplitude_kT = 6.0\n"
    )
    assert main(["simulate", str(config), "--out", str(tmp_path / "sim"), "--quiet"]) == 0
    assert (tmp_path / "sim" / "trajectories.png").stat().st_size > 10_000
    reshuffler = tmp_path / "reshuffler.toml"
    reshuffler.write_text(
        "duration = 1e-7\n[[potentials]]\nkind = 'disorder'\n"
        "rms_kT = 1.0\ncorrelation_length = 50e-9\n"
    )
    assert main(["reshuffle", str(reshuffler), "--out", str(tmp_path / "r"), "--json"]) == 0
    assert (tmp_path / "r" / "device.png").stat().st_size > 10_000


def test_neuron_device_figure_over_the_gate(tmp_path):
    from skygas.neuron import NeuronDevice, neuron_config
    from skygas.neuron.figures import plot_device

    cfg = neuron_config(
        {
            "device": {"chamber_diameter": 400e-9, "conduit_width": 80e-9},
            "rule": {"threshold": 4, "reset_level": 1},
            "potentials": [BUMP],
        }
    )
    run = NeuronDevice(cfg).build(duration=20e-9)
    run.sim.add_skyrmions([[-100e-9, 0.0], [100e-9, 50e-9]])
    run.sim.run(20e-9, record_interval=1e-9)
    path = plot_device(run, tmp_path / "device.png")
    assert path.stat().st_size > 10_000
