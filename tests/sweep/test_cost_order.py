"""The order in which a sweep starts its runs: costliest first (the order never changes
results: every run's seed is fixed by its place in the sweep)."""

from skygas.reshuffler import load_reshuffler_config
from skygas.sweep.execute import relative_cost


def config(**overrides):
    return load_reshuffler_config(preset="default", overrides=overrides)


def test_cost_grows_with_duration_and_falls_with_current():
    base = relative_cost(config())
    assert relative_cost(config(duration=2 * config().duration)) == 2 * base
    # a lower current keeps skyrmions longer in the device: more of them at each step
    assert relative_cost(config(current_density=1e10)) > base
    assert relative_cost(config(current_density=1e12)) < base
    # a larger chamber holds them longer too
    assert relative_cost(config(**{"device.chamber_diameter": 2e-6})) > base
