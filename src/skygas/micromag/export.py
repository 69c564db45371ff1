"""Writing a fitted material as a skygas preset (TOML), and the plot of fitted laws.

The preset is what :func:`skygas.physics.materials.load_material` loads; the plot shows the fitted
laws against their data.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.core.errors import InputError
from skygas.physics.materials import Material, material_from_mapping


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            raise InputError("preset value", value, "a finite number")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a valid TOML basic string
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise InputError("preset value", value, "a number, string, bool or list")


def material_preset(base: Material, **updates) -> Material:
    """``base`` with ``updates``, validated as a :class:`~skygas.physics.materials.Material`.

    ``updates`` are fields such as pair_law, wall_law, skyrmion_radius, dissipation.
    """
    data = {**base.model_dump(), **{k: v for k, v in updates.items() if v is not None}}
    return material_from_mapping(data, field="fitted material")


#: What the first line of a fitted preset says (how a later fit recognises its own file).
PRESET_MARK = "material preset fitted from micromagnetic snapshots"


def write_material_toml(path: str | Path, material: Material, notes: Sequence[str] = ()) -> Path:
    """Write ``material`` as a ``[material]`` table; ``notes`` become header comments."""
    path = Path(path)
    lines = [f"# skygas {__version__} {PRESET_MARK}."]
    lines += [f"# {line}" for note in notes for line in str(note).splitlines()]
    lines.append("[material]")
    for key, value in material.model_dump().items():
        if value is not None:
            value = list(value) if isinstance(value, tuple) else value
            lines.append(f"{key} = {_toml_value(value)}")
    path.write_text("\n".join(lines) + "\n")
    return path


def fit_legend(fit) -> str:
    """A fitted law's legend: its form, then F₀ and the named coefficients, three to a line."""
    values = [f"F₀ = {fit.force_scale * 1e12:.4g} pN"] + [
        f"{name} = {c:.4g}" for name, c in zip(fit.coefficient_names, fit.coefficients, strict=True)
    ]
    lines = [", ".join(values[k : k + 3]) for k in range(0, len(values), 3)]
    return "\n".join([f"fit {fit.formula}", *lines, "(d in skyrmion diameters)"])


def plot_fits(path: str | Path, samples: dict, fits: dict, tables: dict | None = None) -> Path:
    """One panel per law: |F| [pN] against d [diameters].

    The samples, the law tabulated over the measured range (median and interquartile range per bin)
    and the fitted curve, if a law was fitted, its legend the law's form and named values
    (:func:`fit_legend`).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tables = tables or {}
    laws = [law for law in ("pair", "wall") if law in samples]
    fig, axes = plt.subplots(
        1, max(len(laws), 1), figsize=(5 * max(len(laws), 1), 5.6), squeeze=False
    )
    for ax, law in zip(axes[0], laws, strict=False):
        d, force = samples[law]
        positive = force > 0
        ax.semilogy(
            d[positive], force[positive] * 1e12, ".", ms=3, color="0.6", label="Ĝ·ẋ (samples)"
        )
        table = tables.get(law)
        if table is not None:
            # the log axis shows positive medians only; the bars are the quartiles
            shown = table.force > 0
            low = np.clip(table.force - table.force_q25, 0, None)
            high = np.clip(table.force_q75 - table.force, 0, None)
            ax.errorbar(
                table.distance[shown],
                table.force[shown] * 1e12,
                yerr=np.array([low[shown], high[shown]]) * 1e12,
                fmt="o",
                ms=4,
                color="C0",
                capsize=2,
                label="binned median (quartiles)",
            )
        fit = fits.get(law)
        if fit is not None:
            grid = np.linspace(d.min(), d.max(), 200)
            ax.semilogy(grid, fit.magnitude(grid) * 1e12, "r-", label=fit_legend(fit))
        else:
            ax.text(
                0.02,
                0.02,
                "no law fixed by the data: tabulated only",
                transform=ax.transAxes,
                fontsize=7,
            )
        ax.set_xlabel("distance d (skyrmion diameters)")
        ax.set_ylabel("|F| (pN)")
        ax.set_title("skyrmion–skyrmion" if law == "pair" else "skyrmion–wall")
        # below the axes: inside, the form and values of the law would cover its samples
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)
