"""A kind of run added with its study hooks and one registry entry is swept, searched, reported.

The recipe of docs/architecture.md ("a new device", steps 5 and 6), followed with a kind made up
here: a coin flipped ``flips`` times with probability ``p`` of heads. Nothing outside its hooks
and its registry entry is edited, and ``skygas sweep``, ``skygas plot`` and ``skygas optimize``
run it.
"""

from __future__ import annotations

import sys
import textwrap
import types

import numpy as np
import pytest
from pydantic import BaseModel, Field

from skygas.cli import main
from skygas.devices import registry
from skygas.devices.registry import DeviceKind
from skygas.devices.study_hooks import StudyPoints
from skygas.sweep import open_sweep

MODULE = "skygas_test_coin_points"


class CoinConfig(BaseModel):
    """A coin: ``flips`` flips with probability ``p`` of heads."""

    seed: int = Field(0, ge=0, lt=2**63)
    p: float = Field(0.5, ge=0.0, le=1.0)
    flips: int = Field(1000, ge=1)


def _hooks() -> types.ModuleType:
    """The kind's study_points module (docs/architecture.md, step 5)."""
    from skygas.core.config_types import apply_overrides
    from skygas.core.errors import InputError
    from skygas.core.estimates import Estimate

    module = types.ModuleType(MODULE)
    module.NAME = "coin"
    module.QUANTITIES = ("heads_fraction", "n_heads")
    module.DEFAULT_BASE = {}
    module.model = lambda: CoinConfig

    def point(base, overrides, what):
        data = apply_overrides(base, overrides)
        if not 0 <= data.get("p", 0.5) <= 1:
            raise InputError(f"{what}: p", data["p"], "a probability from 0 to 1")
        return CoinConfig(**data)

    def run(config_json):
        config = CoinConfig.model_validate_json(config_json)
        heads = int(np.random.default_rng(config.seed).binomial(config.flips, config.p))
        return {"heads_fraction": heads / config.flips, "n_heads": float(heads)}

    module.point = point
    module.estimate = lambda config: Estimate(steps=config.flips, memory=0.0, seconds=0.0)
    module.run = run
    return module


@pytest.fixture
def coin_kind(monkeypatch):
    """The registry with the coin's entry added (docs/architecture.md, step 6)."""
    monkeypatch.setitem(sys.modules, MODULE, _hooks())
    kinds = {
        **registry.KINDS,
        "coin": DeviceKind(
            name="coin", command="skygas coin", title="Coin", study=StudyPoints(MODULE)
        ),
    }
    monkeypatch.setattr(registry, "KINDS", kinds)


def test_a_new_kind_is_swept_plotted_and_searched(coin_kind, tmp_path):
    sweep_file = tmp_path / "coin.toml"
    sweep_file.write_text(
        textwrap.dedent("""
            [sweep]
            device = "coin"
            seed = 1
            replicas = 3
            [base]
            flips = 4000
            [grid]
            p = [0.1, 0.5, 0.9]
        """)
    )
    store = tmp_path / "coin.zarr"
    assert main(["sweep", str(sweep_file), "--out", str(store), "--serial", "--quiet"]) == 0
    ds = open_sweep(store)
    # a binomial fraction: within 5 standard errors of p (σ = √(p(1−p)/4000) ≤ 0.008)
    p = ds["p"].broadcast_like(ds["done"]).values
    sigma = np.sqrt(p * (1 - p) / 4000)
    assert (np.abs(ds["heads_fraction"].values - p) < 5 * sigma).all()

    figures = tmp_path / "figures"
    assert main(["plot", str(store), "--out", str(figures)]) == 0
    assert (figures / "quantities.png").exists()
    assert "heads_fraction" in (figures / "points.csv").read_text()
    assert "Replica means at each point" in (figures / "report.html").read_text()

    study_file = tmp_path / "search.toml"
    study_file.write_text(
        textwrap.dedent("""
            [study]
            device = "coin"
            seed = 2
            replicas = 1
            startup_trials = 4
            [base]
            flips = 4000
            [space]
            p = { low = 0.0, high = 1.0 }
            [[objectives]]
            name = "distance_from_a_fair_coin"
            expression = "abs(heads_fraction - 0.5)"
            direction = "minimize"
        """)
    )
    out = tmp_path / "search"
    code = main(
        ["optimize", str(study_file), "--out", str(out), "--serial", "--trials", "6", "--quiet"]
    )
    assert code == 0
    assert (out / "report.html").exists()
