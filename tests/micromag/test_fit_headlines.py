"""Every number of ``skygas micromag fit``'s report headline, recomputed here from its files.

The snapshots: two skyrmions of S2 released 1.2 d_sk apart that relax by S2's pair law
(T = 0 Thiele dynamics, integrated by scipy's DOP853 in :mod:`skygas.micromag.synthetic`,
independent of the engine), drawn as ansatz profiles on 2 nm cells and written as OVF files:
61 snapshots of 96 × 96 cells, the command's shortest useful run (seconds). The command runs
once, in-process through the real command line (so that the figure it draws can be read back).

From tracks.csv alone, with code of its own, this file recomputes the measured skyrmion (d_sk
twice the median radius, the median charge and dissipation), the velocities (a cubic
Savitzky–Golay derivative over 9 snapshots, written here with ``np.polyfit``), the Thiele
forces F = (α𝒟k + G ε)·ẋ and the pair samples (the force along the line of centres, averaged
over the two skyrmions), checks forces.csv against them, and fits the pair law in closed form:
ln(F/F₀) = −(a₂d² + a₁d + a₀)/(d + 1) is linear in the coefficients, so the least-squares
coefficients and their covariance s²(XᵀX)⁻¹ need no iteration. The headline's law, F₀, sample
counts, ranges and tabulated law (bins of equal counts, medians) are compared with these, as are
the figure's samples, binned medians and fitted curve, read back from its matplotlib objects.
A stated number agrees when it lies within half a unit of its last printed digit of the
recomputed one (so does its error); a number printed with its trailing zeros dropped (``−1``
for −1.000) is held to the significant digits the report prints (four in the headline, three in
the table).
"""

from __future__ import annotations

import contextlib
import html
import io
import math
import re

import numpy as np
import pandas as pd
import pytest
from tests.micromag.test_cli import _pair_snapshots
from tests.outputs.test_headlines_recomputed import agrees, headline, parse

from skygas.cli import main
from skygas.physics.materials import preset

FILM = 2e-9  # m, the command's default film thickness
#: γ [rad/(s T)] as mumax3 writes it (GammaLL), the convention of skygas's Thiele coefficients
GAMMA = 1.7595e11
WINDOW, ORDER = 9, 3  # the command's default Savitzky–Golay window


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """(output folder, the fit's figure) of ``skygas micromag fit`` on the pair snapshots."""
    import matplotlib.pyplot as plt

    root = tmp_path_factory.mktemp("micromag-fit-headline")
    _, snaps = _pair_snapshots(root / "snaps", preset("S2").pair_law, 40e-9, 61, 96)
    out = root / "out"
    drawn = []
    close = plt.close

    def keep(fig=None):
        drawn.append(fig)
        return close(fig)

    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stdout(io.StringIO()):
        patch.setattr(plt, "close", keep)
        assert main(["micromag", "fit", str(snaps), "--out", str(out)]) == 0
    figures = [
        f
        for f in drawn
        if f is not None and any(ax.get_title() == "skyrmion–skyrmion" for ax in f.axes)
    ]
    assert len(figures) == 1, drawn
    return out, figures[0]


# -- the physics, written here -----------------------------------------------------------------
def savgol_velocity(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """dx/dt by cubic least squares over WINDOW samples; the end windows' cubic at the ends."""
    n, half = len(t), WINDOW // 2
    v = np.empty_like(x)
    for i in range(n):
        lo = min(max(i - half, 0), n - WINDOW)
        window = slice(lo, lo + WINDOW)
        for c in range(x.shape[1]):
            poly = np.polyfit(t[window] - t[i], x[window, c], ORDER)
            v[i, c] = poly[-2]  # the derivative at t[i]
    return v


def recompute(out) -> dict:
    """The measured skyrmion, the pair samples and the least-squares pair law, from tracks.csv."""
    material = preset("S2")
    tracks = pd.read_csv(out / "tracks.csv")
    assert tracks["track"].nunique() == 2
    diameter = 2 * float(np.median(tracks["radius_m"]))
    charge = float(np.median(tracks["charge"]))
    dissipation = float(np.median(tracks["dissipation"]))
    k = material.saturation_magnetization * FILM / GAMMA
    gyro, friction = -4 * math.pi * charge * k, material.damping * dissipation * k
    force_scale = material.exchange_stiffness * FILM / diameter
    per_track = {}
    for track_id, track in tracks.groupby("track"):
        track = track.sort_values("frame")
        t = track["time_s"].to_numpy()
        x = track[["x_m", "y_m"]].to_numpy()
        v = savgol_velocity(t, x)
        # (G ε + a) ẋ = F with ε (u, w) = (w, −u)
        f = np.column_stack(
            [friction * v[:, 0] + gyro * v[:, 1], friction * v[:, 1] - gyro * v[:, 0]]
        )
        per_track[track_id] = (track["frame"].to_numpy(), x, f)
    (fa, xa, ga), (fb, xb, gb) = per_track.values()
    common = np.intersect1d(fa, fb)
    ia, ib = np.searchsorted(fa, common), np.searchsorted(fb, common)
    sep = xa[ia] - xb[ib]
    dist = np.hypot(sep[:, 0], sep[:, 1])
    unit = sep / dist[:, None]
    along = 0.5 * (np.sum(ga[ia] * unit, axis=1) - np.sum(gb[ib] * unit, axis=1))
    d = dist / diameter
    # the law: least squares of ln(F/F₀) over the repulsive samples, linear in (a₂, a₁, a₀)
    repulsive = along > 0
    dr, y = d[repulsive], np.log(along[repulsive] / force_scale)
    design = -np.column_stack([dr * dr, dr, np.ones_like(dr)]) / (dr + 1)[:, None]
    coefficients, *_ = np.linalg.lstsq(design, y, rcond=None)
    residual = y - design @ coefficients
    s2 = residual @ residual / (dr.size - 3)
    errors = np.sqrt(np.diag(s2 * np.linalg.inv(design.T @ design)))
    return {
        "diameter": diameter,
        "charge": charge,
        "dissipation": dissipation,
        "force_scale": force_scale,
        "d": d,
        "force": along,
        "coefficients": coefficients,
        "errors": errors,
        "fit_d": dr,
    }


def equal_count_bins(d: np.ndarray, f: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The samples sorted by distance in ⌈√n⌉ (at most 20) bins, the first ones one larger."""
    order = np.argsort(d, kind="stable")
    n = d.size
    bins = min(20, math.ceil(math.sqrt(n)))
    sizes = [n // bins + (1 if b < n % bins else 0) for b in range(bins)]
    edges = np.concatenate([[0], np.cumsum(sizes)])
    return [(d[order[a:b]], f[order[a:b]]) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def significant(text: str, value: float, digits: int) -> None:
    """``text`` states ``value`` to ``digits`` significant digits (trailing zeros may be gone)."""
    stated = parse(text)
    slack = min(stated.slack, 0.5 * 10.0 ** (math.floor(math.log10(abs(value))) - digits + 1))
    assert abs(stated.value - value) <= slack * (1 + 1e-9), (text, value, digits)


# -- the tests ---------------------------------------------------------------------------------
def test_forces_csv_holds_the_thiele_forces_of_the_tracks(fitted):
    out, _ = fitted
    r = recompute(out)
    table = pd.read_csv(out / "forces.csv")
    assert set(table["law"]) == {"pair"}
    np.testing.assert_allclose(table["distance_diameters"], r["d"], rtol=1e-9)
    np.testing.assert_allclose(
        table["force_N"], r["force"], rtol=1e-6, atol=1e-9 * r["force"].max()
    )


def test_every_headline_number_is_recomputed_from_the_tracks(fitted):
    out, _ = fitted
    r = recompute(out)
    rows, notes = headline(out / "report.html")
    law_row = "pair law |F|(d) = F₀·exp[−(a₂d² + a₁d + a₀)/(d + 1)]"
    expected_rows = {
        law_row,
        "pair law tabulated",
        "skyrmion diameter d_sk",
        "topological charge Q (measured)",
        "dissipation 𝒟 (measured)",
    }
    assert set(rows) == expected_rows, sorted(rows)  # a new row must be checked here too
    # the law: each coefficient ± its error, F₀, the samples fitted and their range
    text = rows[law_row]
    assert not any("constrained" in n or "a₂ ≥" in n for n in notes), notes  # a free fit
    for name, value, error in zip(("a₂", "a₁", "a₀"), r["coefficients"], r["errors"], strict=True):
        m = re.search(rf"{name} = (\S+ ± [\d.]+)", text)
        assert m, (name, text)
        agrees(m.group(1), value, error)
    f0 = re.search(r"F₀ = ([^;]+);", text).group(1)
    assert parse(f0).unit == "N"
    significant(f0, r["force_scale"], 4)
    m = re.search(r"; (\d+) samples over d = ([\d.]+)–([\d.]+) skyrmion diameters$", text)
    assert m, text
    assert int(m.group(1)) == r["fit_d"].size
    agrees(m.group(2), r["fit_d"].min())
    agrees(m.group(3), r["fit_d"].max())
    # the tabulated law: every sample, in ⌈√n⌉ bins
    m = re.fullmatch(
        r"(\d+) samples in (\d+) bins over d = ([\d.]+)–([\d.]+) skyrmion diameters",
        rows["pair law tabulated"],
    )
    assert m, rows["pair law tabulated"]
    bins = equal_count_bins(r["d"], r["force"])
    assert (int(m.group(1)), int(m.group(2))) == (r["d"].size, len(bins))
    agrees(m.group(3), r["d"].min())
    agrees(m.group(4), r["d"].max())
    # the measured skyrmion, to the four significant digits the headline prints
    assert parse(rows["skyrmion diameter d_sk"]).unit == "m"
    significant(rows["skyrmion diameter d_sk"], r["diameter"], 4)
    significant(rows["topological charge Q (measured)"], r["charge"], 4)
    significant(rows["dissipation 𝒟 (measured)"], r["dissipation"], 4)


def test_the_tabulated_law_is_the_median_of_equal_count_bins(fitted):
    out, _ = fitted
    r = recompute(out)
    page = (out / "report.html").read_text()
    start = page.index("<h2>The pair law tabulated over the measured distances</h2>")
    block = page[start : page.index("</table>", start)]
    table = [
        [html.unescape(c) for c in re.findall(r"<td class=n>(.*?)</td>", row)]
        for row in re.findall(r"<tr>(<td.*?)</tr>", block)
    ]
    bins = equal_count_bins(r["d"], r["force"])
    assert len(table) == len(bins)
    for (distance, force, over_f0, count), (d, f) in zip(table, bins, strict=True):
        significant(distance, float(np.median(d)), 3)
        assert parse(force).unit == "N"
        significant(force, float(np.median(f)), 3)
        significant(over_f0, float(np.median(f)) / r["force_scale"], 3)
        assert int(count) == d.size


def test_the_figure_draws_the_samples_the_bins_and_the_law_stated(fitted):
    out, fig = fitted
    r = recompute(out)
    (ax,) = [a for a in fig.axes if a.get_title() == "skyrmion–skyrmion"]
    lines = {line.get_label(): line for line in ax.get_lines()}
    samples = lines["Ĝ·ẋ (samples)"]
    positive = r["force"] > 0
    np.testing.assert_allclose(samples.get_xdata(), r["d"][positive], rtol=1e-9)
    np.testing.assert_allclose(samples.get_ydata(), r["force"][positive] * 1e12, rtol=1e-6)
    # the binned medians (the error bar's data line)
    medians = [
        (float(np.median(d)), float(np.median(f))) for d, f in equal_count_bins(r["d"], r["force"])
    ]
    (binned,) = [c for c in ax.containers if c.get_label() == "binned median (quartiles)"]
    data_line = binned.lines[0]
    np.testing.assert_allclose(data_line.get_xdata(), [m[0] for m in medians if m[1] > 0])
    np.testing.assert_allclose(
        data_line.get_ydata(), [m[1] * 1e12 for m in medians if m[1] > 0], rtol=1e-6
    )
    # the fitted curve: the law recomputed here, over the samples' range
    (curve,) = [line for label, line in lines.items() if label.startswith("fit ")]
    grid = np.asarray(curve.get_xdata())
    assert grid[0] == pytest.approx(r["d"].min()) and grid[-1] == pytest.approx(r["d"].max())
    a2, a1, a0 = r["coefficients"]
    law = r["force_scale"] * np.exp(-(a2 * grid**2 + a1 * grid + a0) / (grid + 1))
    np.testing.assert_allclose(curve.get_ydata(), law * 1e12, rtol=1e-6)
    # its legend names the values drawn
    legend = curve.get_label()
    for name, value in zip(("a₂", "a₁", "a₀"), r["coefficients"], strict=True):
        stated = re.search(rf"{name} = (\S+?)(?:,|\n|$)", legend).group(1)
        significant(stated, value, 4)
    significant(re.search(r"F₀ = (\S+ pN)", legend).group(1), r["force_scale"], 4)
