"""Microscope-like movies of simulated skyrmions: the synthetic data the tracker is tested on.

Each skyrmion is a disc of its diameter d (its dark or bright core) seen through a microscope
whose point-spread function is a Gaussian of standard deviation σ_psf. The disc convolved with
the Gaussian has the radial profile

    f(r) = (1/σ²) ∫₀^R ρ exp(−(r² + ρ²)/2σ²) I₀(rρ/σ²) dρ,      R = d/2,

(1 at the centre of a disc much wider than σ), tabulated once and sampled at the pixel centres.
A frame is

    I(x, y, t) = B·L(x, y, t) + s·C·Σ_k f(|r − r_k(t)|),

with the background level B [counts], the contrast C [counts], s = −1 for dark skyrmions
(the usual Kerr or X-ray picture of cores against the film) or +1 for bright ones, and an
illumination L = 1 + a·(cos θ(t)·X + sin θ(t)·Y) whose gradient (a fraction ``a`` across the
field, X, Y ∈ [−1, 1]) turns once over the movie: the slow drift of a real lamp. Photon shot
noise (Poisson, ``photons`` photons at the background level) and Gaussian read noise
(``noise`` counts) are added, and the result is rounded and clipped to uint8 or uint16.

**The pixel grid.** Pixel (row i, column j) is centred at x = x₀ + j·p, y = y₀ + i·p: row 0 is
the lowest y, so trackpy's (x, y) times the pixel size p is the simulation's frame shifted by
(x₀, y₀), with the same handedness (a flipped image would turn the Hall angle's sign). The
field of view is the device's bounding box plus a margin; (x₀, y₀), p and the frame interval
are recorded in the TIFF (ImageJ ``finterval``, the resolution tags) and in the sidecar JSON
(:func:`write_movie`).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from skygas.core.errors import InputError

#: the pixel types a movie can be written in, and their largest count
DTYPES = {"uint8": 255, "uint16": 65535}


@dataclass(frozen=True)
class RenderSettings:
    """How a movie is drawn; lengths in metres, levels in counts of the output type.

    ``pixel_size`` [m]; ``psf_sigma`` [m] (default: a quarter of the skyrmion diameter, a
    resolution-limited picture); ``contrast`` ``"dark"`` or ``"bright"``; ``background`` and
    ``depth`` (C) [counts] (default: 60 % and 35 % of the type's range); ``noise`` [counts]
    Gaussian; ``photons`` at the background level (0: no shot noise); ``illumination_drift``
    a; ``margin`` [m] around the device (default: two skyrmion diameters); ``dtype``; ``seed``
    of the noise.
    """

    pixel_size: float
    psf_sigma: float | None = None
    contrast: str = "dark"
    background: float | None = None
    depth: float | None = None
    noise: float = 2.0
    photons: float = 0.0
    illumination_drift: float = 0.0
    margin: float | None = None
    dtype: str = "uint8"
    seed: int = 0

    def checked(self) -> RenderSettings:
        """These settings, each refused (:class:`InputError`) when outside its range."""
        from skygas.movies.track_run import check_length

        _positive("--pixel-size", self.pixel_size, "a pixel size > 0 in metres, e.g. 14e-9")
        check_length("--pixel-size", self.pixel_size)
        if self.psf_sigma is not None:
            _positive("--psf-sigma", self.psf_sigma, "a PSF standard deviation > 0 in metres")
            check_length("--psf-sigma", self.psf_sigma)
        if self.contrast not in ("dark", "bright"):
            raise InputError("--contrast", self.contrast, "dark or bright")
        if self.dtype not in DTYPES:
            raise InputError("--dtype", self.dtype, f"one of {', '.join(DTYPES)}")
        top = DTYPES[self.dtype]
        for name, value in (("--background", self.background), ("--depth", self.depth)):
            if value is not None and not (np.isfinite(value) and 0 < value <= top):
                raise InputError(name, value, f"a level in (0, {top}] counts of {self.dtype}")
        for name, value in (
            ("--noise", self.noise),
            ("--photons", self.photons),
            ("--illumination-drift", self.illumination_drift),
        ):
            if not (np.isfinite(value) and value >= 0):
                raise InputError(name, value, "a number >= 0")
        if self.illumination_drift >= 1:
            raise InputError(
                "--illumination-drift", self.illumination_drift, "a fraction below 1, e.g. 0.05"
            )
        if self.margin is not None and not (np.isfinite(self.margin) and self.margin >= 0):
            raise InputError("--margin", self.margin, "a margin >= 0 in metres")
        if self.margin:
            check_length("--margin", self.margin)
        return self


def _positive(field: str, value, allowed: str) -> None:
    if value is None or not np.isfinite(value) or value <= 0:
        raise InputError(field, value, allowed)


def disc_profile(radius: float, sigma: float, r: np.ndarray) -> np.ndarray:
    """The disc of ``radius`` convolved with a unit-area Gaussian of ``sigma``, at distances ``r``.

    f(r) = (1/σ²) ∫₀^R ρ exp(−(r − ρ)²/2σ²) i0e(rρ/σ²) dρ (the exponentially scaled Bessel
    function keeps the integrand finite); f → 1 at the centre of a disc much wider than σ.
    All lengths in the same unit.

    Parameters
    ----------
    radius : float
        The disc's radius R (0: the Gaussian itself, peak 1).
    sigma : float
        The Gaussian's standard deviation σ > 0.
    r : ndarray
        Distances from the disc's centre.

    Returns
    -------
    ndarray
        f(r), same shape as ``r``.
    """
    from scipy.special import i0e

    r = np.asarray(r, float)
    if radius <= 0:
        return np.exp(-(r**2) / (2 * sigma**2))
    from scipy.integrate import simpson

    rho = np.linspace(0.0, radius, 2 * int(16 * radius / sigma) + 257)  # 32+ points per σ
    rr = r.reshape(-1, 1)
    integrand = rho * np.exp(-((rr - rho) ** 2) / (2 * sigma**2)) * i0e(rr * rho / sigma**2)
    return (simpson(integrand, x=rho, axis=1) / sigma**2).reshape(r.shape)


@dataclass(frozen=True)
class Grid:
    """The pixel grid: ``origin`` (x₀, y₀) [m] of pixel (0, 0), ``pixel_size`` [m], ``shape``."""

    origin: tuple[float, float]
    pixel_size: float
    shape: tuple[int, int]

    def to_pixels(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Positions [m] → trackpy's (x, y) [px] (column, row)."""
        p = self.pixel_size
        return (np.asarray(x) - self.origin[0]) / p, (np.asarray(y) - self.origin[1]) / p


def grid_for(bounds: tuple[float, float, float, float], pixel_size: float, margin: float) -> Grid:
    """The grid covering ``bounds`` (x0, y0, x1, y1) [m] and ``margin`` [m], an even size."""
    x0, y0, x1, y1 = bounds
    nx = 2 * int(np.ceil((x1 - x0 + 2 * margin) / pixel_size / 2))
    ny = 2 * int(np.ceil((y1 - y0 + 2 * margin) / pixel_size / 2))
    if nx * ny > 4096 * 4096:
        raise InputError(
            "--pixel-size",
            pixel_size,
            f"a pixel size giving at most 4096 × 4096 pixels (this one gives {nx} × {ny})",
            "choose a larger pixel size",
        )
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    origin = (cx - (nx - 1) / 2 * pixel_size, cy - (ny - 1) / 2 * pixel_size)
    return Grid(origin, pixel_size, (ny, nx))


def render_frames(
    positions,
    grid: Grid,
    diameter: float,
    settings: RenderSettings,
    progress=None,
) -> np.ndarray:
    """The movie of skyrmions at ``positions``: (frames, rows, columns) of ``settings.dtype``.

    Parameters
    ----------
    positions : sequence of (N_t, 2) arrays
        The skyrmions' (x, y) [m] in each frame (any number per frame).
    grid : Grid
        The pixel grid.
    diameter : float
        The skyrmion diameter d [m].
    settings : RenderSettings
        How to draw (checked here).
    progress : callable, optional
        Called with no argument after each frame.

    Returns
    -------
    ndarray
        The frames; row i at y = y₀ + i·p.
    """
    s = settings.checked()
    top = DTYPES[s.dtype]
    p = grid.pixel_size
    sigma = (s.psf_sigma if s.psf_sigma is not None else diameter / 4) / p
    radius = diameter / 2 / p
    background = s.background if s.background is not None else 0.6 * top
    depth = s.depth if s.depth is not None else 0.35 * top
    sign = -1.0 if s.contrast == "dark" else 1.0
    reach = int(np.ceil(radius + 5 * sigma))  # f < 4e-6 beyond
    table_r = np.linspace(0.0, reach * np.sqrt(2) + 1, 2048)
    table_f = disc_profile(radius, sigma, table_r)
    ny, nx = grid.shape
    X = np.linspace(-1, 1, nx)[None, :]
    Y = np.linspace(-1, 1, ny)[:, None]
    rng = np.random.default_rng(s.seed)
    n_frames = len(positions)
    out = np.empty((n_frames, ny, nx), np.uint8 if s.dtype == "uint8" else np.uint16)
    offsets = np.arange(-reach, reach + 1)
    for t, xy in enumerate(positions):
        theta = 2 * np.pi * t / max(n_frames, 1)
        light = 1 + s.illumination_drift * (np.cos(theta) * X + np.sin(theta) * Y)
        spots = np.zeros((ny, nx))
        xy = np.asarray(xy, float).reshape(-1, 2)
        for px, py in zip(*grid.to_pixels(xy[:, 0], xy[:, 1]), strict=True):
            if not (np.isfinite(px) and np.isfinite(py)):
                continue
            j0, i0 = int(round(px)), int(round(py))
            cols, rows = j0 + offsets, i0 + offsets
            cols = cols[(cols >= 0) & (cols < nx)]
            rows = rows[(rows >= 0) & (rows < ny)]
            if not len(cols) or not len(rows):
                continue
            dist = np.hypot(cols[None, :] - px, rows[:, None] - py)
            spots[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1] += np.interp(
                dist, table_r, table_f
            )
        image = background * light + sign * depth * spots
        if s.photons > 0:  # shot noise: Poisson in photons, photons per count fixed by B
            gain = s.photons / background
            image = rng.poisson(np.clip(image, 0, None) * gain) / gain
        if s.noise > 0:
            image = image + rng.normal(0.0, s.noise, image.shape)
        out[t] = np.clip(np.rint(image), 0, top)
        if progress is not None:
            progress()
    return out


def write_movie(path: str | Path, frames: np.ndarray, metadata: dict) -> Path:
    """Write ``frames`` as a compressed TIFF stack and its sidecar JSON ``<stem>.json``.

    The TIFF carries the pixel size (resolution tags, µm, and ImageJ's ``unit``) and the frame
    interval (ImageJ's ``finterval`` [s]), so Fiji and :func:`skygas.movies.reading.open_movie`
    read them; the sidecar holds ``metadata`` in full (``pixel_size_m``, ``frame_interval_s``,
    ``origin_m``, the settings, the provenance). Both are written atomically.

    Parameters
    ----------
    path : str or Path
        The ``.tif`` (or ``.tiff``) file.
    frames : ndarray
        (frames, rows, columns), uint8 or uint16.
    metadata : dict
        Needs ``pixel_size_m`` and ``frame_interval_s``.

    Returns
    -------
    Path
        The TIFF file.
    """
    import tifffile

    from skygas.runs.run_driver import write_atomic, write_json

    path = Path(path)
    p_um = metadata["pixel_size_m"] * 1e6
    description = {
        "spacing": 1.0,
        "unit": "um",
        "finterval": metadata["frame_interval_s"],
        "axes": "TYX",
    }

    def write(tmp: Path) -> None:
        tifffile.imwrite(
            tmp,
            frames,
            imagej=True,
            resolution=(1 / p_um, 1 / p_um),
            metadata=description,
            compression="zlib",
            predictor=True,
        )

    write_atomic(path, write)
    write_json(sidecar_path(path), metadata)
    return path


def sidecar_path(movie: str | Path) -> Path:
    """The JSON beside a movie file that records its pixel size and frame interval."""
    movie = Path(movie)
    return movie.with_suffix(".json")


def settings_record(settings: RenderSettings) -> dict:
    """The settings as JSON-able dict."""
    return json.loads(json.dumps(asdict(settings)))


def render_run(
    record,
    settings: RenderSettings,
    *,
    stride: int = 1,
    max_frames: int | None = None,
    start: float = 0.0,
    progress: bool = True,
) -> tuple[np.ndarray, dict]:
    """The movie of a finished run and its metadata (see :func:`write_movie`).

    Parameters
    ----------
    record : RunRecord
        The run (:func:`skygas.outputs.records.load_run`).
    settings : RenderSettings
        How to draw.
    stride : int
        Every ``stride``-th recorded frame: the frame interval is ``stride`` record intervals.
    max_frames : int, optional
        The most frames (default: all).
    start : float
        The first time shown [s]: frames recorded earlier are left out (a burn-in, while a
        gas placed at random relaxes).
    progress : bool
        Show a progress bar (on a terminal).

    Returns
    -------
    frames : ndarray
        (frames, rows, columns).
    metadata : dict
        ``pixel_size_m``, ``frame_interval_s``, ``origin_m`` (x₀, y₀ of pixel (0, 0)),
        ``shape``, ``skyrmion_diameter_m``, ``temperature_K``, ``contrast``, the settings and the
        provenance of the run.
    """
    from tqdm import tqdm

    settings = settings.checked()
    if stride < 1:
        raise InputError("--stride", stride, "an integer >= 1")
    if max_frames is not None and max_frames < 2:
        raise InputError("--max-frames", max_frames, "an integer >= 2")
    if not (np.isfinite(start) and start >= 0):
        raise InputError("--start", start, "a time >= 0 in seconds")
    frames = record.frames
    first = int(np.searchsorted(frames.time, start * (1 - 1e-9)))
    indices = np.arange(first, frames.n_frames, stride)[:max_frames]
    if len(indices) < 2:
        raise InputError(
            "RUN",
            str(record.path),
            f"a run with at least 2 recorded frames from {start:g} s at stride {stride} "
            f"(it recorded {frames.n_frames}, up to {frames.time[-1]:.4g} s)",
            "run it longer, or lower --start or --stride",
        )
    times = frames.time[indices]
    interval = float(f"{np.median(np.diff(times)):.12g}")  # the record interval, not its rounding
    diameter = float(record.skyrmion_diameter)
    margin = settings.margin if settings.margin is not None else 2 * diameter
    bounds = tuple(record.outline.bounds)  # [m]
    grid = grid_for(bounds, settings.pixel_size, margin)
    positions = [frames.frame(int(f))[1] for f in indices]
    bar = tqdm(total=len(indices), unit="frame", desc="rendered", leave=False, disable=not progress)
    try:
        movie = render_frames(positions, grid, diameter, settings, progress=bar.update)
    finally:
        bar.close()
    metadata = {
        "pixel_size_m": settings.pixel_size,
        "frame_interval_s": interval,
        "origin_m": list(grid.origin),
        "shape": [len(indices), *grid.shape],
        "pixel_convention": "pixel (row i, column j) is centred at x = x0 + j*p, y = y0 + i*p",
        "skyrmion_diameter_m": diameter,
        "temperature_K": record.config.get("temperature"),
        "first_time_s": float(times[0]),
        "stride": stride,
        "settings": settings_record(settings),
        "source": str(record.path),
        "provenance": record.provenance(),
    }
    return movie, metadata


def outline_mask(outline, grid: Grid) -> np.ndarray:
    """The device on the movie's pixel grid: True at pixel centres inside the outline."""
    ny, nx = grid.shape
    x = grid.origin[0] + grid.pixel_size * np.arange(nx)
    y = grid.origin[1] + grid.pixel_size * np.arange(ny)
    gx, gy = np.meshgrid(x, y)
    return outline.contains(gx, gy)


def outline_vertices(outline, grid: Grid) -> np.ndarray:
    """The outline's vertices (x, y) [m] in the tracks' frame: pixel (0, 0) at the origin.

    A point at trackpy's (x, y) [px] is at (x·p, y·p) [m] in this frame. For a device of
    several pieces, the largest.
    """
    region = outline.region
    if hasattr(region, "geoms"):
        region = max(region.geoms, key=lambda g: g.area)
    xy = np.asarray(region.exterior.coords) * 1e-9
    return xy - np.asarray(grid.origin)


def write_outline(movie_path: str | Path, outline, grid: Grid) -> tuple[Path, Path]:
    """Write ``<stem>-outline.png`` (mask, 255 inside) and ``<stem>-outline.csv`` (x,y [m]).

    The mask is on the movie's pixel grid, its row i at y = i·p like the frames; the polygon is
    in the tracks' frame (:func:`outline_vertices`).
    """
    from PIL import Image

    from skygas.runs.run_driver import write_atomic

    movie_path = Path(movie_path)
    png = movie_path.with_name(f"{movie_path.stem}-outline.png")
    csv = movie_path.with_name(f"{movie_path.stem}-outline.csv")
    mask = (outline_mask(outline, grid) * 255).astype(np.uint8)
    write_atomic(png, lambda tmp: Image.fromarray(mask).save(tmp, format="PNG"))
    xy = outline_vertices(outline, grid)
    text = "x,y\n" + "".join(f"{x:.10e},{y:.10e}\n" for x, y in xy)
    write_atomic(csv, lambda tmp: tmp.write_text(text))
    return png, csv


def true_model(record) -> dict | None:
    """The simulated gas's own parameters (for checking an inference), or None.

    Temperature, material, the Thiele coefficients, the free diffusion constant
    D = k_BT α𝒟k/((α𝒟k)² + G²) [m²/s], the pair and wall laws and the potentials, as the run's
    configuration gives them. Only for ``skygas simulate`` runs.
    """
    from skygas.devices.registry import KINDS

    device = KINDS.get(record.kind)
    # a plain simulation (the one kind driven uniformly): a device's gas has its own fields
    if device is None or not device.uniform_drive or record.config.get("temperature") is None:
        return None
    from skygas.runs.config import SimulationConfig

    config = SimulationConfig.model_validate_json(json.dumps(record.config))
    thiele = config.thiele_parameters()
    temperature = float(record.config["temperature"])
    material = config.resolved_material()
    return {
        "temperature_K": temperature,
        "material": record.config.get("material"),
        "diffusion_constant_m2_s": thiele.diffusion_constant(temperature),
        "thiele": thiele.as_record(),
        "pair_law": list(material.pair_law),
        "wall_law": list(material.wall_law),
        "potentials": record.config.get("potentials", []),
        "seed": record.seed,
    }


def write_true_landscape(movie_path: str | Path, record, grid: Grid) -> Path | None:
    """Write the run's energy landscape on the movie's pixels as ``<stem>-landscape.nc``.

    U/k_BT at the pixel centres, NaN outside the device, its mean over the device subtracted
    (a landscape is fixed up to a constant), on coordinates ``x``, ``y`` [m] in the tracks'
    frame (pixel (0, 0) at the origin, as :func:`outline_vertices`): the answer that a
    Boltzmann inversion of the movie's tracks is compared with. None (nothing written) for a
    run without a landscape or at T = 0.

    Returns
    -------
    Path or None
        The file written.
    """
    import xarray as xr

    from skygas.core import units
    from skygas.runs.run_driver import write_netcdf

    temperature = record.config.get("temperature") or 0.0
    field_ = record.landscape_fn() if record.landscape_fn is not None else None
    if field_ is None or not field_.terms or temperature <= 0:
        return None
    ny, nx = grid.shape
    p = grid.pixel_size
    xs, ys = p * np.arange(nx), p * np.arange(ny)
    gx, gy = np.meshgrid(xs + grid.origin[0], ys + grid.origin[1])
    energy, _ = field_.energy_and_force(np.column_stack([gx.ravel(), gy.ravel()]))
    u = energy.reshape(ny, nx) / (units.BOLTZMANN * temperature)
    inside = outline_mask(record.outline, grid)
    u = np.where(inside, u - u[inside].mean(), np.nan).astype(np.float32)  # 7 digits: plenty
    ds = xr.Dataset(
        {"U": (("y", "x"), u, {"units": "k_BT", "temperature_K": temperature})},
        coords={"x": ("x", xs, {"units": "m"}), "y": ("y", ys, {"units": "m"})},
        attrs={
            "title": "the simulated gas's energy landscape on the movie's pixels",
            "frame": "the tracks' frame: pixel (0, 0) at x = y = 0; mean over the device 0",
            "source": str(record.path),
        },
    )
    path = Path(movie_path)
    return write_netcdf(ds, path.with_name(f"{path.stem}-landscape.nc"))
