"""Every number of a report's headline, recomputed here from the run's result files.

Each device command runs its shortest real run once (module fixtures: simulate, reshuffle,
neuron, reservoir, sweep); the test reads the headline block of report.html (label → text),
parses each number (value, error, unit) and recomputes it with code of its own from the
records the run wrote: the bit streams, trajectories, count trace and sweep store, never the
summary's own figure. A stated number agrees when it lies within half a unit of its last printed
digit of the recomputed one (so does its error). Where a figure shows a headline number
(the fullest chamber, the fitted D₀, the count trace, the sweep's fits), the data the figure
draws are read back from its matplotlib objects and compared too.
"""

from __future__ import annotations

import contextlib
import html
import io
import json
import math
import re
import statistics
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from skygas.cli import main

# -- reading the headline ----------------------------------------------------------------------
_SUPERSCRIPT = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺", "0123456789-+")
_PREFIXES = {"a": -18, "f": -15, "p": -12, "n": -9, "µ": -6, "m": -3, "k": 3, "M": 6, "G": 9}
_PREFIXED = {"s", "m", "J", "W", "Hz", "V", "A", "N", "S", "Ω", "C"}
_NUMBER = r"[−-]?\d+(?:\.\d+)?"
_QUANTITY = re.compile(
    rf"\(?(?P<v>{_NUMBER})(?: ± (?P<e>{_NUMBER}))?\)?"
    r"(?:×10(?P<p>[⁻⁺]?[⁰¹²³⁴⁵⁶⁷⁸⁹]+))?(?: (?P<u>[^\s(),;:]+))?"
)


@dataclass(frozen=True)
class Stated:
    """A number as the report prints it, in SI units, with half a unit of its last digit."""

    value: float
    error: float | None
    unit: str
    #: half a unit of the last printed digit of the value and of the error (SI units)
    slack: float
    error_slack: float
    text: str


def _decimals(number: str) -> int:
    return len(number.split(".")[1]) if "." in number else 0


def _float(number: str) -> float:
    return float(number.replace("−", "-"))


def parse(text: str) -> Stated:
    """The first number of ``text`` (``0.071 ± 0.037``, ``(8.2 ± 1.4)×10⁻⁹ m²/s``, ``9.155 fJ``)."""
    m = _QUANTITY.search(text)
    assert m, f"no number in {text!r}"
    power = int(m["p"].translate(_SUPERSCRIPT)) if m["p"] else 0
    unit = m["u"] or ""
    if unit[1:] in _PREFIXED and unit[:1] in _PREFIXES:
        power += _PREFIXES[unit[0]]
        unit = unit[1:]
    scale = 10.0**power
    value, error = _float(m["v"]) * scale, _float(m["e"]) * scale if m["e"] else None
    if unit == "%":
        scale, value, error = scale / 100, value / 100, None if error is None else error / 100
    return Stated(
        value,
        error,
        unit,
        0.5 * 10.0 ** -_decimals(m["v"]) * scale,
        0.5 * 10.0 ** -_decimals(m["e"]) * scale if m["e"] else 0.0,
        text,
    )


def agrees(text: str, value: float, error: float | None = None, unit: str | None = None) -> Stated:
    """Assert that the number ``text`` states is ``value`` (± ``error``) within its digits."""
    stated = parse(text)
    tolerance = stated.slack + 1e-9 * abs(value)
    assert abs(stated.value - value) <= tolerance, (text, value)
    if error is not None:
        assert stated.error is not None, (text, "no error stated for", error)
        assert abs(stated.error - error) <= stated.error_slack + 1e-9 * error, (text, error)
    if unit is not None:
        assert stated.unit == unit, (text, unit)
    return stated


def _numbers(text: str) -> list[Stated]:
    """Every number of ``text``, in order (each with its unit)."""
    found, rest = [], text
    while (m := _QUANTITY.search(rest)) is not None:
        found.append(parse(rest[m.start() :]))
        rest = rest[m.end() :]
    return found


def headline(report: Path) -> tuple[dict[str, str], list[str]]:
    """The headline block of ``report``: its rows (label → text) and its notes."""
    page = report.read_text()
    start = page.index("<section class=headline id=headline>")
    block = page[start : page.index("</section>", start)]
    rows = {
        html.unescape(k): html.unescape(v)
        for k, v in re.findall(r"<tr><th>(.*?)</th><td class=n>(.*?)</td></tr>", block)
    }
    return rows, [html.unescape(n) for n in re.findall(r"<p>(.*?)</p>", block)]


def captions(report: Path) -> list[str]:
    """The captions of the report's figures, in order."""
    return [
        html.unescape(c) for c in re.findall(r"<figcaption>(.*?)</figcaption>", report.read_text())
    ]


@contextlib.contextmanager
def figures_drawn():
    """The figures drawn while inside, by file name (and ``report N`` for the report's own)."""
    from skygas.outputs import report as report_module

    drawn: dict[str, Figure] = {}
    save, png = Figure.savefig, report_module._figure_png

    def savefig(self, fname, *args, **kwargs):
        # write_figure saves to ".NAME.partial.png" first: the name is NAME.png
        drawn[Path(str(fname)).name.lstrip(".").replace(".partial", "")] = self
        return save(self, fname, *args, **kwargs)

    def figure_png(fig):
        drawn[f"report {sum(k.startswith('report') for k in drawn)}"] = fig
        return png(fig)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(Figure, "savefig", savefig)
        patch.setattr(report_module, "_figure_png", figure_png)
        yield drawn


def _run(argv: list) -> str:
    """``skygas ARGV`` in this process; its standard output."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main([str(a) for a in argv]) == 0, argv
    return out.getvalue()


def _line(fig: Figure, label: str):
    """The line labelled ``label`` of ``fig`` (any axes)."""
    found = [line for ax in fig.axes for line in ax.get_lines() if line.get_label() == label]
    assert found, (label, [line.get_label() for ax in fig.axes for line in ax.get_lines()])
    return found[0]


# -- the statistics, written here ------------------------------------------------------------
def phi(b: np.ndarray, c: np.ndarray) -> float:
    """Pearson's ρ of two bit sequences (0 if either is constant)."""
    b, c = b.astype(float), c.astype(float)
    pb, pc, pbc = b.mean(), c.mean(), (b * c).mean()
    variance = pb * (1 - pb) * pc * (1 - pc)
    return 0.0 if variance <= 0 else (pbc - pb * pc) / math.sqrt(variance)


def block_jackknife(b: np.ndarray, c: np.ndarray, blocks: int = 20) -> float:
    """Standard error of ρ leaving out one of ``blocks`` contiguous blocks of pairs at a time."""
    n = len(b)
    if n < 2 * blocks:
        return math.nan
    edges = [int(e) for e in np.linspace(0, n, blocks + 1)]
    keep = np.ones(n, bool)
    values = []
    for j in range(blocks):
        keep[:] = True
        keep[edges[j] : edges[j + 1]] = False
        values.append(phi(b[keep], c[keep]))
    values = np.array(values)
    return math.sqrt((blocks - 1) / blocks * np.sum((values - values.mean()) ** 2))


def clopper_pearson(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """The exact binomial interval of k successes in n."""
    from scipy.stats import beta

    alpha = 1 - confidence
    low = 0.0 if k == 0 else beta.ppf(alpha / 2, k, n - k + 1)
    high = 1.0 if k == n else beta.ppf(1 - alpha / 2, k + 1, n - k)
    return float(low), float(high)


def wilson(right: int, n: int, z: float = 1.0) -> tuple[float, float]:
    """Wilson's score interval (68 % for z = 1)."""
    a = right / n
    centre = (a + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(a * (1 - a) / n + z * z / (4 * n * n))
    return centre - half, centre + half


def peak_occupancy(t_in, up_in, t_out, up_out) -> tuple[int, int]:
    """The most skyrmions each chamber held: +1 per injection, −1 per read-out, in time order.

    Events at the same instant all count before the chamber is looked at.
    """
    peaks = []
    for chamber in (True, False):
        times = np.concatenate([t_in[up_in == chamber], t_out[up_out == chamber]])
        steps = np.concatenate(
            [np.ones((up_in == chamber).sum()), -np.ones((up_out == chamber).sum())]
        )
        order = np.argsort(times, kind="stable")
        level, peak, k = 0, 0, 0
        while k < len(order):
            now = times[order[k]]
            while k < len(order) and times[order[k]] == now:
                level += steps[order[k]]
                k += 1
            peak = max(peak, level)
        peaks.append(int(peak))
    return peaks[0], peaks[1]


# ============================================================================== simulate
SIMULATE = """
seed = 2
temperature = 300.0
duration = 12e-9
record_interval = 1e-9
material = "S2"
[geometry]
kind = "chamber"
chamber_diameter = 1024e-9
conduit_width = 100e-9
conduit_length = 50e-9
closed = true
[skyrmions]
random_count = 10
min_separation = 1.5
"""


@pytest.fixture(scope="module")
def simulate(tmp_path_factory):
    """A 12 ns closed-chamber run of 10 skyrmions, its report and the figures drawn."""
    root = tmp_path_factory.mktemp("simulate")
    (root / "run.toml").write_text(SIMULATE)
    with figures_drawn() as drawn:
        _run(["simulate", root / "run.toml", "--out", root / "out", "--quiet"])
    return root / "out", drawn


def short_time_diffusion(x: np.ndarray, y: np.ndarray, dt: float) -> tuple[float, float]:
    """D₀ = Σ τ MSD(τ) / 4 Σ τ² over frame lags 1–4, ± its delete-one-skyrmion jackknife error.

    x, y: (frames, skyrmions) [m], NaN where a skyrmion is absent; the MSD pools every skyrmion
    and every time origin.
    """
    lags = np.arange(1, 5)
    tau = lags * dt
    # per skyrmion and lag: the number of displacements and the sum of their squares
    count = np.zeros((x.shape[1], len(lags)))
    square = np.zeros_like(count)
    for i, lag in enumerate(lags):
        d2 = (x[lag:] - x[:-lag]) ** 2 + (y[lag:] - y[:-lag]) ** 2
        ok = np.isfinite(d2)
        count[:, i] = ok.sum(axis=0)
        square[:, i] = np.where(ok, d2, 0.0).sum(axis=0)

    def d0(n, s):
        return float(np.sum(tau * s / n) / (4 * np.sum(tau**2)))

    value = d0(count.sum(0), square.sum(0))
    active = np.flatnonzero(count.sum(1) > 0)
    left_out = np.array([d0(count.sum(0) - count[p], square.sum(0) - square[p]) for p in active])
    p = len(active)
    error = math.sqrt((p - 1) / p * np.sum((left_out - left_out.mean()) ** 2))
    return value, error


def test_simulate_headline_is_recomputed_from_the_trajectories(simulate):
    out, drawn = simulate
    rows, _ = headline(out / "report.html")
    ds = xr.open_dataset(out / "trajectories.nc")
    x, y = ds.x.values, ds.y.values
    assert rows["skyrmions at the start"] == str(int(np.isfinite(x[0]).sum()))
    assert rows["skyrmions at the end"] == str(int(np.isfinite(x[-1]).sum()))
    assert rows["skyrmions that left through a port"] == str(ds.sizes["exit"])
    escapes = rows["wall escapes (steps that would have crossed a wall)"]
    assert escapes == str(ds.attrs["wall_escapes"])
    dt = float(np.diff(ds.time.values).mean())
    d0, d0_error = short_time_diffusion(x, y, dt)
    stated = agrees(rows["short-time D₀"], d0, d0_error, "m²/s")
    assert "drift removed" not in rows["short-time D₀"]  # a closed chamber has no drive
    # the record is 12 frame intervals: no plateau over a half-decade of lags ten frames long
    assert len(ds.time) - 1 < 40 and rows["long-time D_eff"].startswith(
        "none (the record is too short"
    )
    # the figure of MSD(τ)/4τ draws the D₀ the headline states (nm²/ns = 10⁻⁹ m²/s)
    line = _line(drawn["report 0"], "D₀ (short lags)")
    assert np.allclose(line.get_ydata(), d0 * 1e9) and abs(d0 - stated.value) <= stated.slack
    # the trajectories figure draws every skyrmion's path, and says how many
    axes = drawn["trajectories.png"].axes[0]
    paths = [(line.get_xdata(), line.get_ydata()) for line in axes.get_lines()]
    for k in range(ds.sizes["skyrmion"]):
        ok = np.isfinite(x[:, k])
        path = (x[ok, k] * 1e6, y[ok, k] * 1e6)
        assert any(np.array_equal(p[0], path[0]) and np.array_equal(p[1], path[1]) for p in paths)
    assert axes.get_title().startswith(f"{ds.sizes['skyrmion']} skyrmions")
    print("simulate:", {"D0": d0, "D0_error": d0_error, "skyrmions": ds.sizes["skyrmion"]})


# ============================================================================== reshuffle
@pytest.fixture(scope="module")
def reshuffle(tmp_path_factory):
    """2 µs of the reshuffler with 800 nm chambers (about 400 bits), its report and figures."""
    out = tmp_path_factory.mktemp("reshuffle") / "out"
    with figures_drawn() as drawn:
        _run(
            [
                "reshuffle",
                "--out",
                out,
                "--quiet",
                "--duration",
                "2e-6",
                "--chamber-diameter",
                "8e-7",
            ]
        )
    return out, drawn


def reshuffler_streams(ds: xr.Dataset) -> dict[str, np.ndarray]:
    """The input bits in injection order and the output bits in read-out order, with times."""
    skyrmion = ds.event_skyrmion.values
    injected = np.flatnonzero(skyrmion >= 0)
    t_in = ds.event_injection_time.values[injected]
    order = injected[np.lexsort((injected, t_in))]
    read = np.argsort(ds.detection_time.values, kind="stable")
    return {
        "b": ds.input_bit.values[order].astype(bool),
        "t_in": ds.event_injection_time.values[order],
        "id_in": skyrmion[order],
        "c": ds.detection_up.values[read].astype(bool),
        "t_out": ds.detection_time.values[read],
        "id_out": ds.detection_skyrmion.values[read],
    }


def lag_scan(b: np.ndarray, c: np.ndarray, max_lag: int) -> tuple[int, float, int]:
    """ρ(ℓ) of b_k against c_(k+ℓ) for |ℓ| ≤ max_lag: the lag of the largest |ρ|, ρ, its pairs.

    Ties go to the smaller |ℓ| (then to the negative lag).
    """
    best = None
    for lag in sorted(range(-max_lag, max_lag + 1), key=abs):
        first, stop = max(0, -lag), min(len(b), len(c) - lag)
        rho = phi(b[first:stop], c[first + lag : stop + lag])
        if best is None or abs(rho) > abs(best[1]):
            best = (lag, rho, stop - first)
    assert best is not None
    return best


def test_reshuffler_headline_is_recomputed_from_the_bit_streams(reshuffle):
    out, drawn = reshuffle
    rows, notes = headline(out / "report.html")
    ds = xr.open_dataset(out / "reshuffler.nc")
    config = json.loads(ds.attrs["config_json"])
    s = reshuffler_streams(ds)
    b, c = s["b"], s["c"]
    n = min(len(b), len(c))
    rho, rho_error = phi(b[:n], c[:n]), block_jackknife(b[:n], c[:n])
    agrees(rows["input–output correlation ρ"], rho, rho_error, "")
    assert any("20 blocks" in note for note in notes)
    # p_in over every input bit, p_out over every read-out, with its exact 95 % interval
    p_in = float(ds.input_bit.values.mean())
    agrees(rows["input p-value p_in"], p_in)
    p_out = rows["output p-value p_out"]
    low, high = clopper_pearson(int(c.sum()), len(c))
    numbers = _numbers(p_out)
    agrees(p_out, float(c.mean()))
    assert "95 % interval" in p_out
    for stated, value in zip(numbers[-2:], (low, high), strict=True):
        assert abs(stated.value - value) <= stated.slack + 1e-12, (p_out, low, high)
    # power: the current J·w·t through each chamber's resistance, twice; energy per bit: power
    # times the injection interval
    current = json.loads(ds.attrs["current_json"])
    amps = (
        config["current_density"]
        * config["device"]["conduit_width"]
        * current["conductor_thickness_m"]
    )
    power = 2 * amps**2 * current["resistance_ohm"]
    agrees(rows["electrical power"], power, unit="W")
    agrees(rows["energy per bit"], power * config["injection"]["interval"], unit="J")
    # transit: each read-out's time less its skyrmion's injection time
    injected_at = dict(zip(s["id_in"].tolist(), s["t_in"].tolist(), strict=True))
    transit = s["t_out"] - np.array([injected_at[k] for k in s["id_out"].tolist()])
    agrees(rows["mean transit time"], float(transit.mean()), unit="s")
    agrees(rows["median transit time"], float(np.median(transit)), unit="s")
    # every skyrmion accounted for: those still present are in the last snapshot
    present = len(b) - len(c)
    assert ds.snapshot_time.values[-1] == pytest.approx(config["duration"])
    assert int(ds.snapshot_count.values[-1]) == present
    assert (
        rows["skyrmions"]
        == f"{len(b)} injected = {len(c)} read out + {present} present + 0 annihilated"
    )
    # the fullest chamber, from the events; the occupancy figure draws that peak
    up, down = peak_occupancy(s["t_in"], s["b"], s["t_out"], s["c"])
    assert rows["largest occupancy of a chamber"] == str(max(up, down))
    occupancy = drawn["occupancy.png"].axes[0]
    drawn_peak = {line.get_label(): max(line.get_ydata()) for line in occupancy.get_lines()}
    assert {k.split(" ")[0]: v for k, v in drawn_peak.items()} == {"UP": up, "DOWN": down}
    # the lag scan: ρ(ℓ) pairs input bit k with read-out k + ℓ, explained where it is shown
    max_lag = min(config["output"]["max_lag"], n - 2)
    lag, lag_rho, pairs = lag_scan(b, c, max_lag)
    scan = rows[f"largest |ρ(ℓ)| over the lags ℓ = −{max_lag} … {max_lag}"]
    sign = "−" if lag < 0 else ""
    assert scan.startswith(f"ρ({sign}{abs(lag)}) = "), scan
    agrees(scan.split(" = ", 1)[1], lag_rho)
    assert f"over {pairs} pairs" in scan
    lags = 2 * max_lag + 1
    noise = statistics.NormalDist().inv_cdf((1 + 0.5 ** (1 / lags)) / 2) / math.sqrt(pairs)
    agrees(scan.split("reach ", 1)[1], noise)
    assert f"at one of the {lags} lags" in scan
    explained = " ".join(notes)
    assert "(k+ℓ)-th bit read out" in explained and "injection interval" in explained
    assert f"{config['injection']['interval'] * 1e9:g} ns" in explained and "transit" in explained
    assert not re.search(r"[−+-]0\b", scan + explained)  # no signed zero lag
    # the running correlation ends at ρ
    running = drawn["running_correlation.png"].axes[0].get_lines()[0].get_ydata()
    assert running[-1] == pytest.approx(rho)
    print(
        "reshuffle:",
        {
            "rho": rho,
            "rho_error": rho_error,
            "p_in": p_in,
            "p_out": float(c.mean()),
            "p_out_95": (low, high),
            "power_W": power,
            "mean_transit_s": float(transit.mean()),
            "peak_up_down": (up, down),
            "best_lag": (lag, lag_rho, pairs, noise),
        },
    )


def test_each_occupancy_figure_says_how_it_was_sampled(reshuffle):
    out, _ = reshuffle
    found = captions(out / "report.html")
    assert any("every read-out and injection" in c for c in found), found
    assert any(re.search(r"at each recorded frame \(every \d+ ns\)", c) for c in found), found


def test_the_occupancy_figure_draws_the_fullest_chamber_whatever_the_stored_grid(
    reshuffle, tmp_path
):
    # a 100 µs run stores its occupancy every 200 ns, 40 injections apart: here every 100 ns
    from skygas.reshuffler.figures import plot_occupancy

    out, _ = reshuffle
    ds = xr.open_dataset(out / "reshuffler.nc")
    s = reshuffler_streams(ds)
    up, down = peak_occupancy(s["t_in"], s["b"], s["t_out"], s["c"])
    with figures_drawn() as drawn:
        plot_occupancy(ds.isel(occupancy_time=slice(None, None, 25)), tmp_path / "occupancy.png")
    lines = drawn["occupancy.png"].axes[0].get_lines()
    assert {line.get_label().split(" ")[0]: max(line.get_ydata()) for line in lines} == {
        "UP": up,
        "DOWN": down,
    }
    summary = json.loads((out / "summary.json").read_text())
    assert max(up, down) == summary["max_occupancy"]


# ============================================================================== neuron
NEURON = """
duration = 200e-9
[device]
chamber_diameter = 400e-9
conduit_width = 80e-9
[rule]
threshold = 4
reset_level = 1
release_time = 10e-9
[annihilation]
base_rate = 2e7
compression_sensitivity = 0.0
[transfer]
rates = [5e7, 2e8, 6e8]
duration = 100e-9
[[inputs]]
kind = 'poisson'
rate = 3e8
"""


@pytest.fixture(scope="module")
def neuron(tmp_path_factory):
    """200 ns of a 400 nm neuron firing every 30 ns, with a three-point transfer curve."""
    root = tmp_path_factory.mktemp("neuron")
    (root / "neuron.toml").write_text(NEURON)
    with figures_drawn() as drawn:
        _run(["neuron", root / "neuron.toml", "--out", root / "out", "--quiet"])
    return root / "out", drawn


def lif_rate(
    rate: float, tau: float, theta: float, reset: float, release: float, refractory: float
):
    """A deterministic LIF's firing rate at a steady input ``rate`` (0 below θ/τ)."""
    drive = rate * tau
    if drive <= theta:
        return 0.0
    climb = tau * math.log((drive - reset) / (drive - theta))
    return 1.0 / (release + max(refractory, climb))


def lif_spikes(injections, tau, theta, reset, duration, dt, release, refractory) -> np.ndarray:
    """Spike times of an LIF on a grid of step dt, one unit per injection."""
    n = int(duration / dt) + 1
    jumps = np.zeros(n)
    for t in injections:
        jumps[min(int(t / dt), n - 1)] += 1
    v, spikes, held, blocked = 0.0, [], -1.0, -1.0
    for k in range(n):
        t = k * dt
        v = reset if t < held else v * math.exp(-dt / tau) + jumps[k]
        if v >= theta and t >= blocked:
            spikes.append(t)
            v, held, blocked = reset, t + release, t + release + refractory
    return np.array(spikes)


def test_neuron_headline_is_recomputed_from_the_count_trace(neuron):
    out, drawn = neuron
    rows, _ = headline(out / "report.html")
    trace = np.load(out / "trace.npz")
    config = json.loads(str(trace["config_json"]))
    duration = config["duration"]
    spikes = trace["spikes"]
    rate = agrees(
        rows["output spike rate"], len(spikes) / duration, math.sqrt(len(spikes)) / duration, "Hz"
    )
    assert f"({len(spikes)} output spikes in " in rows["output spike rate"] and rate.value > 0
    driven = sum(i["weight"] * i["rate"] for i in config["inputs"])
    agrees(rows["input rate"], driven, unit="Hz")
    # counts: what went in, what left through the gate, what was annihilated, what is left
    t, count, gate = trace["time"], trace["count"], trace["gate_open"]
    deaths = trace["annihilations"]
    assert rows["skyrmions injected"] == str(len(trace["injections"]))
    assert rows["skyrmions emitted"] == str(len(trace["emissions"]))
    assert rows["skyrmions annihilated"] == str(len(deaths))
    assert len(trace["injections"]) == len(trace["emissions"]) + len(deaths) + count[-1]
    assert rows["largest count in the chamber"] == str(int(count.max()))
    # the LIF fit: τ = ∫N dt over the closed gate / the deaths then (± τ/√deaths); θ and V_r the
    # median counts at the gate's openings and closings
    closed = ~gate[:-1]
    exposure = float(np.sum(count[:-1] * np.diff(t) * closed))
    at = np.clip(np.searchsorted(t, deaths, side="right") - 1, 0, len(t) - 1)
    dead = int(np.sum(~gate[at]))
    tau, tau_error = exposure / dead, exposure / dead / math.sqrt(dead)
    opens = np.flatnonzero(gate[1:] & ~gate[:-1]) + 1
    closes = np.flatnonzero(~gate[1:] & gate[:-1]) + 1
    assert np.allclose(t[opens], spikes)
    theta, reset = float(np.median(count[opens])), float(np.median(count[closes]))
    lif = rows["LIF fit: membrane time τ, threshold θ, reset V_r"]
    agrees(lif.split("τ = ")[1], tau, tau_error, "s")
    agrees(lif.split("θ = ")[1], theta)
    agrees(lif.split("V_r = ")[1], reset)
    release = float(np.mean(t[closes] - t[opens[: len(closes)]]))
    refractory = config["rule"]["refractory_time"]
    # the transfer curve: R² of the LIF's rates against the device's
    summary = json.loads((out / "summary.json").read_text())
    curve = summary["transfer_curve"]
    measured = np.array(curve["firing_rate_Hz"])
    predicted = np.array(
        [lif_rate(r, tau, theta, reset, release, refractory) for r in curve["input_rate_Hz"]]
    )
    r2_text = rows["transfer curve: R² of the LIF prediction"]
    if np.ptp(measured) == 0:
        assert r2_text.startswith("none (undefined: the device fired at the same rate")
    else:
        r2 = 1 - np.sum((measured - predicted) ** 2) / np.sum((measured - measured.mean()) ** 2)
        agrees(r2_text, float(r2))
        assert f"over {len(measured)} input rates" in r2_text
    # the device's spikes matched by a spike of the LIF driven by the same injections
    dt = float(np.median(np.diff(t)))
    lif_times = lif_spikes(
        trace["injections"], tau, theta, reset, duration, dt, release, refractory
    )
    window = max(10 * dt, 0.1 * release)
    matched = sum(bool(len(lif_times)) and np.min(np.abs(lif_times - s)) <= window for s in spikes)
    agrees(rows["device spikes matched by the LIF"], matched / len(spikes), unit="%")
    # the count trace draws every reading; the device figure shows what its caption says
    drawn_count = _line(drawn["count_trace.png"], "skyrmions in the device").get_ydata()
    assert max(drawn_count) == count.max() and len(drawn_count) == len(count)
    device = next(c for c in captions(out / "report.html") if c.startswith("The neuron over"))
    title = drawn["device.png"].axes[0].get_title()
    assert "skyrmions at the end" in title  # the run recorded no positions
    assert "with the skyrmions present at the end" in device, device
    assert "with the skyrmions' trajectories" not in device and "recorded no positions" in device
    print(
        "neuron:",
        {
            "rate_Hz": len(spikes) / duration,
            "tau_s": (tau, tau_error),
            "theta": theta,
            "reset": reset,
            "matched": matched / len(spikes),
            "transfer": (measured.tolist(), predicted.tolist()),
        },
    )


# ============================================================================== reservoir
RESERVOIR = """
hold_time = 1e-7
[sensors]
sample_interval = 2e-9
[study]
n_inputs = 16
temporal_inputs = 16
workers = 1
"""


@pytest.fixture(scope="module")
def reservoir(tmp_path_factory):
    """The reservoir's study on 16 inputs held 100 ns each."""
    root = tmp_path_factory.mktemp("reservoir")
    (root / "reservoir.toml").write_text(RESERVOIR)
    _run(["reservoir", root / "reservoir.toml", "--out", root / "out", "--quiet"])
    return root / "out"


def check_accuracy(text: str, right: int, n: int) -> None:
    """``text`` states the accuracy right/n with its 68 % Wilson interval, inside 0–100 %.

    An accuracy written "a ± e %" (the standard error of chance once stood there) fails: its
    interval is not the accuracy's own and may pass 100 %.
    """
    stated = parse(text)
    assert abs(stated.value - right / n) <= stated.slack + 1e-12, (text, right, n)
    assert stated.error is None, f"{text!r}: an accuracy with a ± error, not its interval"
    m = re.search(rf"\((?P<lo>{_NUMBER})–(?P<hi>{_NUMBER}) %\)", text)
    assert m, f"{text!r}: no 68 % interval"
    lo, hi = wilson(right, n)
    assert 0 <= _float(m["lo"]) <= 100 * stated.value <= _float(m["hi"]) <= 100, text
    for printed, value in ((m["lo"], lo), (m["hi"], hi)):
        assert abs(_float(printed) - 100 * value) <= 0.05 + 1e-9, (text, lo, hi)


def test_the_accuracy_check_refuses_the_chance_levels_error():
    # "98.3 ± 3.2 %": 236 of 240 right, with the standard error of a 51 % chance level
    with pytest.raises(AssertionError):
        check_accuracy("98.3 ± 3.2 % on 240 test inputs (chance 51 %)", 236, 240)
    check_accuracy("98.3 % (97.3–99.0 %) on 240 test inputs (chance 51 %)", 236, 240)


def _right(score: dict) -> int:
    right = score["accuracy"] * score["n_test"]
    assert abs(right - round(right)) < 1e-9  # an accuracy is a count of right answers
    return round(right)


def test_reservoir_headline_is_recomputed_from_its_scores_and_drive(reservoir):
    rows, _ = headline(reservoir / "report.html")
    s = json.loads((reservoir / "summary.json").read_text())
    xor = s["boolean"]["XOR"]
    check_accuracy(rows["XOR test accuracy"], _right(xor), xor["n_test"])
    assert f"on {xor['n_test']} test inputs (chance " in rows["XOR test accuracy"]
    agrees(rows["XOR test accuracy"].split("chance ")[1], xor["chance"], unit="%")
    scores = [_right(b) / b["n_test"] for b in s["boolean"].values()]
    assert len(scores) == 16
    agrees(rows["mean accuracy of the 16 functions"], float(np.mean(scores)), unit="%")
    for k, score in s["temporal"]["recall"].items():
        check_accuracy(
            rows[f"recall of input a, {k} input(s) back"], _right(score), score["n_test"]
        )
    parity = s["temporal"]["parity_last_two"]
    check_accuracy(rows["parity of the last two inputs"], _right(parity), parity["n_test"])
    # energy per operation: each symbol's V·G·V held for the hold time, averaged over symbols
    drive = s["device"]["drive"]
    g = np.array(drive["conductance_matrix_S"])
    energies = [
        float(v @ g @ v) * s["hold_time_s"]
        for v in (
            np.array([symbol["potentials_V"][c] for c in drive["contacts"]])
            for symbol in drive["symbols"].values()
        )
    ]
    agrees(rows["energy per operation"], float(np.mean(energies)), unit="J")
    print("reservoir:", {"xor": (_right(xor), xor["n_test"]), "energy_J": float(np.mean(energies))})


# ============================================================================== sweep
SWEEP = """
[sweep]
seed = 11
replicas = 2
[base]
preset = "paper"
duration = 1e-6
[base.device]
chamber_diameter = 5e-7
[base.output]
trajectory_window = 0.0
running_points = 20
[base.current]
cell_size = 5e-9
[grid]
current_density = [1.4e11, 1.6e11, 1.8e11, 2.0e11, 2.2e11]
"signal.p" = [0.62]
"""
J0 = 1e11  # A/m², the unit of J in the fits


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """Five currents × 2 replicas of 1 µs in 500 nm chambers; its store, report and figures."""
    root = tmp_path_factory.mktemp("sweep")
    (root / "sweep.toml").write_text(SWEEP)
    _run(["sweep", root / "sweep.toml", "--out", root / "s.zarr", "--serial", "--quiet"])
    with figures_drawn() as drawn:
        printed = _run(["plot", root / "s.zarr", "--out", root / "figures"])
    return root, drawn, printed


def replica_points(store: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """J, the replica mean of ρ and its standard error, per current (one p-value)."""
    from skygas.sweep import open_sweep

    ds = open_sweep(store)
    rho = ds["correlation"].where(ds["done"] == 1).squeeze(drop=True)
    values = rho.transpose(..., "replica").values
    mean = np.nanmean(values, axis=-1)
    count = np.sum(np.isfinite(values), axis=-1)
    sem = np.nanstd(values, axis=-1, ddof=1) / np.sqrt(count)
    return ds["current_density"].values, mean, sem


def free_exponent(j, mean, sem) -> tuple[float, float, int]:
    """β of ρ/(1 − ρ) ∝ J^β over the points with 0 < ρ < 1, weighted; error ×√(χ²/dof) above 1."""
    ok = (mean > 0) & (mean < 1)
    x, r = np.log(j[ok] / J0), mean[ok]
    y, sigma = np.log(r / (1 - r)), sem[ok] / (r * (1 - r))
    w = 1 / sigma
    a = np.column_stack([np.ones_like(x), x]) * w[:, None]
    coef = np.linalg.solve(a.T @ a, a.T @ (y * w))
    cov = np.linalg.inv(a.T @ a)
    chi2 = float(np.sum(((y - coef[0] - coef[1] * x) * w) ** 2)) / (len(x) - 2)
    return float(coef[1]), float(math.sqrt(cov[1, 1] * max(chi2, 1.0))), int(ok.sum())


def paper_fit(j, mean, sem) -> dict:
    """ρ = c_A/(c_B + (J/J₀)^(−3/2)), c ≥ 0, weighted by the replica errors; χ²/dof."""
    from scipy.optimize import least_squares

    x = j / J0

    def model(c, x):
        return c[0] / (c[1] + x**-1.5)

    fit = least_squares(lambda c: (model(c, x) - mean) / sem, (1.0, 1.0), bounds=(0, np.inf))
    chi2 = float(np.sum(fit.fun**2)) / (len(x) - 2)
    cov = np.linalg.pinv(fit.jac.T @ fit.jac) * max(chi2, 1.0)
    errors = np.sqrt(np.diag(cov))
    constrained = all(0 < e < abs(c) for c, e in zip(fit.x, errors, strict=True))
    return {"c": fit.x, "errors": errors, "chi2_dof": chi2, "constrained": constrained}


def test_sweep_headline_and_figure_are_recomputed_from_the_store(sweep):
    root, drawn, printed = sweep
    rows, notes = headline(root / "figures" / "report.html")
    j, mean, sem = replica_points(root / "s.zarr")
    beta, beta_error, n = free_exponent(j, mean, sem)
    stated = rows["exponent of ρ/(1−ρ) ∝ Jᵝ"]
    agrees(stated, beta, beta_error)
    assert f"over {n} points (paper: 1.5)" in stated
    fit = paper_fit(j, mean, sem)
    paper = rows["paper's fit ρ = c_A/(c_B + (J/J₀)⁻¹·⁵)"]
    figure = drawn["reshuffler.png"].axes[0]
    labels = [line.get_label() for line in figure.get_lines()]
    if fit["constrained"]:
        agrees(paper.split("c_A = ")[1], fit["c"][0], fit["errors"][0])
        agrees(paper.split("c_B = ")[1], fit["c"][1], fit["errors"][1])
        agrees(paper.split("χ²/dof = ")[1], fit["chi2_dof"])
        assert any(label.startswith("paper's fit") for label in labels), labels
    else:
        # a fit the headline calls unconstrained is not drawn, and the caption says so
        assert paper.startswith("none (the points do not constrain it"), paper
        assert not any(label.startswith("paper's fit") for label in labels), labels
        figure_caption = captions(root / "figures" / "report.html")[0]
        assert "Not drawn: the paper's fit" in figure_caption, figure_caption
    # J₀ defined where it is shown: in the headline and the figure's legend
    assert any("J₀ = 10¹¹ A/m²" in note for note in notes), notes
    assert all("J₀ = 10¹¹ A/m²" in label for label in labels if "J₀" in label)
    free = [label for label in labels if label.startswith("free fit")]
    assert free and f"{beta:.2f}" in free[0]
    # the command line's β points to where the paper's 3/2 is discussed
    line = next(line for line in printed.splitlines() if "β = " in line)
    agrees(line.split("β = ")[1], beta, beta_error)
    assert "docs/paper-reproduction.md" in line
    # the lag numbers of the details figure: whole lags, never "+0" or "-0"
    lag_panel = drawn["reshuffler_details.png"].axes[3]
    marks = [text.get_text() for text in lag_panel.texts]
    assert marks and not any(re.fullmatch(r"[−+-]0(\.0*)?", m) for m in marks), marks
    print(
        "sweep:",
        {
            "points": list(zip(j.tolist(), mean.tolist(), sem.tolist(), strict=True)),
            "beta": (beta, beta_error, n),
            "paper_fit": fit,
        },
    )
