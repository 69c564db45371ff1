"""The kinds of external potential U(x, y), each a validated record that samples itself.

Every kind is configured in TOML as ``[[potentials]]`` with ``kind = "..."`` and in Python as the
class of the same name; lengths are in metres, energies in joules (``amplitude``) or in units of
k_BT at the run's temperature (``amplitude_kT``). :meth:`sample` gives U and its derivatives
∂U/∂x, ∂U/∂y, ∂²U/∂x∂y at the nodes of the engine's grid (internal units: pN·nm and nm), which
:class:`~skygas.fields.landscape.field.LandscapeField` adds up and the engine interpolates
(:mod:`skygas.fields.landscape.hermite`). Analytic kinds give exact derivatives; ``disorder`` gives
spectral ones; ``grid`` files are fitted with a bicubic spline; a ``band`` given as a polygon
uses second-order finite differences of its smoothed indicator; ``edge_stray_field`` (the
film's edge stray field, made from the device's outline) fourth-order ones.
"""

from __future__ import annotations

import hashlib
import io
import math
import zipfile
from pathlib import Path
from typing import Annotated, ClassVar, Literal, NamedTuple

import numpy as np
from pydantic import (
    ConfigDict,
    Field,
    ValidationInfo,
    field_validator,
    model_validator,
)

from skygas.core import units
from skygas.core.config_types import StrictModel, register_union_tags
from skygas.core.memo import Memo
from skygas.core.resources import require_memory

# The edge stray-field energy per film, spacing and parameters (see skygas.core.memo): a sweep's
# runs of one device share it (two FFT convolutions, ~1 s for the paper's chamber).
_STRAY_ENERGY = Memo("edge_stray_field", maxsize=4)

Length = Annotated[float, Field(gt=0, allow_inf_nan=False)]
Energy = Annotated[float, Field(allow_inf_nan=False)]
Point = tuple[
    Annotated[float, Field(allow_inf_nan=False)], Annotated[float, Field(allow_inf_nan=False)]
]


class Samples(NamedTuple):
    """U [pN·nm], ∂U/∂x, ∂U/∂y [pN] and ∂²U/∂x∂y [pN/nm] at the grid's nodes (ny, nx)."""

    u: np.ndarray
    ux: np.ndarray
    uy: np.ndarray
    uxy: np.ndarray


class SampleContext(NamedTuple):
    """What sampling needs besides the potential.

    Node coordinates (ny, nx) [nm], k_BT [pN·nm] at the run's temperature, a seed for the random
    kinds, and, for the kinds made by the device's shape (:attr:`_Kind.needs_film`), ``inside``: the
    film's share of each node's cell (ny, nx), 1 inside the outline, 0 outside, fractions along the
    walls (``None`` when no term needs it).
    """

    x: np.ndarray
    y: np.ndarray
    kt: float
    seed: np.random.SeedSequence
    inside: np.ndarray | None = None


class _Kind(StrictModel):
    """A potential: strict like every configuration section, and immutable.

    Immutable because a run's landscape is sampled once from it.
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)

    #: True for a term made by the device's outline (it reads ``SampleContext.inside``); its
    #: curvature limits the time step only where skyrmion centres can be, like the wall law's
    #: slope (:meth:`~skygas.fields.landscape.field.LandscapeField.max_curvature`).
    needs_film: ClassVar[bool] = False

    def sample(self, ctx: SampleContext) -> Samples:  # pragma: no cover - every kind has one
        raise NotImplementedError


def _energy(value_j, value_kt, kt: float, name: str) -> float:
    """An energy given in J or in k_BT, in pN·nm."""
    if value_kt is not None:
        if kt <= 0:
            from skygas.core.errors import InputError

            raise InputError(
                f"{name}_kT",
                value_kt,
                f"a temperature > 0 (or {name} in joules): k_BT is zero at T = 0",
            )
        return float(value_kt) * kt
    return float(value_j) * units.J_TO_PN_NM


def _exactly_one(model, name: str) -> None:
    """Refuse a model that gives both or neither of ``name`` (J) and ``name_kT`` (k_BT)."""
    if (getattr(model, name) is None) == (getattr(model, f"{name}_kT") is None):
        raise ValueError(f"give exactly one of {name} (J) or {name}_kT (units of k_BT)")


class _Amplitude(_Kind):
    amplitude: Energy | None = None  # [J]
    amplitude_kT: Energy | None = None  # [k_BT]

    @model_validator(mode="after")
    def _one_amplitude(self):
        _exactly_one(self, "amplitude")
        return self

    def energy_scale(self, kt: float) -> float:
        return _energy(self.amplitude, self.amplitude_kT, kt, "amplitude")


class Gaussian(_Amplitude):
    """U = A exp(−|r − c|²/(2σ²)): a bump (A > 0) or a well (A < 0).

    Of width ``sigma`` [m] at ``center`` [m].
    """

    kind: Literal["gaussian"] = "gaussian"
    center: Point
    sigma: Length

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm)."""
        s = self.sigma * units.M_TO_NM
        dx = ctx.x - self.center[0] * units.M_TO_NM
        dy = ctx.y - self.center[1] * units.M_TO_NM
        u = self.energy_scale(ctx.kt) * np.exp(-(dx * dx + dy * dy) / (2 * s * s))
        return Samples(u, -dx / s**2 * u, -dy / s**2 * u, dx * dy / s**4 * u)


class Periodic(_Amplitude):
    """U = A cos(2π r·n̂/λ): a washboard of ``wavelength`` λ [m] along ``direction`` n̂."""

    kind: Literal["periodic"] = "periodic"
    wavelength: Length
    direction: Point = (1.0, 0.0)

    @model_validator(mode="after")
    def _direction(self):
        if math.hypot(*self.direction) == 0:
            raise ValueError("direction must be a non-zero vector")
        return self

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm)."""
        n = np.asarray(self.direction) / math.hypot(*self.direction)
        kx, ky = 2 * math.pi / (self.wavelength * units.M_TO_NM) * n
        phase = kx * ctx.x + ky * ctx.y
        a = self.energy_scale(ctx.kt)
        c, s = a * np.cos(phase), a * np.sin(phase)
        return Samples(c, -kx * s, -ky * s, -kx * ky * c)


def _smooth_box(v, lo, hi, edge):
    """½[tanh((v − lo)/e) − tanh((v − hi)/e)] and its first two derivatives in v."""
    a, b = np.tanh((v - lo) / edge), np.tanh((v - hi) / edge)
    sa, sb = 1 - a * a, 1 - b * b  # sech²
    return (0.5 * (a - b), 0.5 * (sa - sb) / edge, (-sa * a + sb * b) / edge**2)


class Band(_Kind):
    """A barrier (``height`` > 0) or trough with smooth edges: the gate of a conduit.

    Given either as ``start`` and ``end`` [m] of its centre line plus a ``width`` [m] (a
    rectangle, smooth and exact), or as a ``polygon`` [m]. Its profile rises over
    ``edge_width`` [m] (tanh edges). ``height`` in J or ``height_kT`` in k_BT. A band can be
    switched off and on during a run (:meth:`LandscapeField.set_enabled`).
    """

    kind: Literal["band"] = "band"
    height: Energy | None = None
    height_kT: Energy | None = None
    edge_width: Length
    start: Point | None = None
    end: Point | None = None
    width: Length | None = None
    polygon: list[Point] | None = None
    name: str = "band"

    @model_validator(mode="after")
    def _shape(self):
        _exactly_one(self, "height")
        segment = self.start is not None and self.end is not None and self.width is not None
        if segment == (self.polygon is not None):
            raise ValueError("give either start, end and width, or polygon")
        if segment and self.start == self.end:
            raise ValueError("start and end must differ")
        if self.polygon is not None and len(self.polygon) < 3:
            raise ValueError("a polygon needs at least three points")
        return self

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm)."""
        h = _energy(self.height, self.height_kT, ctx.kt, "height")
        e = self.edge_width * units.M_TO_NM
        if self.polygon is not None:
            return self._sample_polygon(ctx, h, e)
        p0 = np.asarray(self.start) * units.M_TO_NM
        p1 = np.asarray(self.end) * units.M_TO_NM
        length = float(np.hypot(*(p1 - p0)))
        tx, ty = (p1 - p0) / length
        nx, ny = -ty, tx
        rx, ry = ctx.x - p0[0], ctx.y - p0[1]
        s, n = rx * tx + ry * ty, rx * nx + ry * ny
        assert self.width is not None  # a segment band (checked by _shape)
        w = self.width * units.M_TO_NM
        g, g1, g2 = _smooth_box(s, 0.0, length, e)
        f, f1, f2 = _smooth_box(n, -w / 2, w / 2, e)
        u = h * g * f
        ux = h * (g1 * f * tx + g * f1 * nx)
        uy = h * (g1 * f * ty + g * f1 * ny)
        uxy = h * (g2 * f * tx * ty + g1 * f1 * (tx * ny + ty * nx) + g * f2 * nx * ny)
        return Samples(u, ux, uy, uxy)

    def _sample_polygon(self, ctx: SampleContext, h: float, e: float) -> Samples:
        import shapely

        poly = shapely.Polygon(np.asarray(self.polygon) * units.M_TO_NM)
        points = shapely.points(ctx.x.ravel(), ctx.y.ravel())
        d = shapely.distance(poly.boundary, points).reshape(ctx.x.shape)
        d = np.where(shapely.contains(poly, points).reshape(ctx.x.shape), d, -d)
        u = h * 0.5 * (1 + np.tanh(d / e))
        spacing = float(ctx.x[0, 1] - ctx.x[0, 0])
        uy, ux = np.gradient(u, spacing)
        uxy = np.gradient(ux, spacing, axis=0)
        return Samples(u, ux, uy, uxy)


class RandomPinning(_Kind):
    """Gaussian wells of width ``sigma`` [m] at random positions, ``density`` [1/m²] on average.

    Their depths are drawn from a normal law of mean ``depth`` and spread ``depth_spread`` (J, or
    ``depth_kT`` / ``depth_spread_kT`` in k_BT; negative draws are clipped to 0), all drawn from the
    run's seed.
    """

    kind: Literal["random_pinning"] = "random_pinning"
    density: Annotated[float, Field(ge=0, allow_inf_nan=False)]
    sigma: Length
    depth: Annotated[float, Field(ge=0, allow_inf_nan=False)] | None = None
    depth_kT: Annotated[float, Field(ge=0, allow_inf_nan=False)] | None = None
    depth_spread: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.0
    depth_spread_kT: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.0

    @model_validator(mode="after")
    def _one_depth(self):
        _exactly_one(self, "depth")
        return self

    def wells(self, ctx: SampleContext) -> tuple[np.ndarray, np.ndarray]:
        """Centres (k, 2) [nm] and depths (k,) [pN·nm] of the wells over the grid's area."""
        rng = np.random.default_rng(ctx.seed)
        x0, x1 = float(ctx.x.min()), float(ctx.x.max())
        y0, y1 = float(ctx.y.min()), float(ctx.y.max())
        area_m2 = (x1 - x0) * (y1 - y0) / units.M_TO_NM**2
        expected = self.density * area_m2
        # each well: its centre (2 floats) and depth, before any Poisson draw that would overflow
        require_memory(
            "random_pinning.density",
            self.density,
            (expected + 6 * math.sqrt(expected) + 1) * 3 * 8,
            f"about {expected:.3g} pinning wells over this {area_m2:.3g} m² area",
            "use a density in wells per m² (e.g. 1e14 for one per 100 nm square)",
        )
        count = rng.poisson(expected)
        centres = rng.uniform((x0, y0), (x1, y1), size=(count, 2))
        if self.depth_kT is not None:
            mean = _energy(None, self.depth_kT, ctx.kt, "depth")
            spread = (
                _energy(None, self.depth_spread_kT, ctx.kt, "depth_spread")
                if self.depth_spread_kT
                else 0.0
            )
        else:
            assert self.depth is not None  # exactly one of depth, depth_kT (_one_depth)
            mean = self.depth * units.J_TO_PN_NM
            spread = self.depth_spread * units.J_TO_PN_NM
        depths = (
            np.maximum(rng.normal(mean, spread, count), 0.0) if spread else np.full(count, mean)
        )
        return centres, depths

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm), summed over wells."""
        s = self.sigma * units.M_TO_NM
        out = [np.zeros_like(ctx.x) for _ in range(4)]
        spacing = float(ctx.x[0, 1] - ctx.x[0, 0])
        reach = int(math.ceil(6 * s / spacing))  # exp(−18) of the depth beyond 6σ
        gx0, gy0 = float(ctx.x[0, 0]), float(ctx.y[0, 0])
        ny, nx = ctx.x.shape
        for (cx, cy), depth in zip(*self.wells(ctx), strict=True):
            i, j = int(round((cx - gx0) / spacing)), int(round((cy - gy0) / spacing))
            rows = slice(max(j - reach, 0), min(j + reach + 1, ny))
            cols = slice(max(i - reach, 0), min(i + reach + 1, nx))
            dx, dy = ctx.x[rows, cols] - cx, ctx.y[rows, cols] - cy
            u = -depth * np.exp(-(dx * dx + dy * dy) / (2 * s * s))
            for target, value in zip(
                out, (u, -dx / s**2 * u, -dy / s**2 * u, dx * dy / s**4 * u), strict=True
            ):
                target[rows, cols] += value
        return Samples(*out)


class Disorder(_Kind):
    """A Gaussian random field of standard deviation ``rms``, drawn from the run's seed.

    ``rms`` in J, or ``rms_kT`` in k_BT; covariance rms²·exp(−r²/(2ξ²)), ξ = ``correlation_length``
    [m].

    Synthesised by FFT on the grid, padded by 4ξ on each side so that the periodic wrap of the
    transform leaves no correlation across the device; derivatives are spectral (exact for the
    synthesised field).
    """

    kind: Literal["disorder"] = "disorder"
    rms: Annotated[float, Field(ge=0, allow_inf_nan=False)] | None = None
    rms_kT: Annotated[float, Field(ge=0, allow_inf_nan=False)] | None = None
    correlation_length: Length

    @model_validator(mode="after")
    def _one_rms(self):
        _exactly_one(self, "rms")
        return self

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm), spectral."""
        rms = _energy(self.rms, self.rms_kT, ctx.kt, "rms")
        xi = self.correlation_length * units.M_TO_NM
        h = float(ctx.x[0, 1] - ctx.x[0, 0])
        ny, nx = ctx.x.shape
        pad = int(math.ceil(4 * xi / h))
        shape = (ny + 2 * pad, nx + 2 * pad)
        white = np.random.default_rng(ctx.seed).standard_normal(shape)
        # white noise of unit variance per node filtered with K(r) = exp(−r²/(2s²)),
        # s = ξ/√2, has the covariance ΣK²·exp(−r²/(2ξ²)): divide by √(ΣK²)
        s = xi / math.sqrt(2)
        oy = np.minimum(np.arange(shape[0]), shape[0] - np.arange(shape[0])) * h
        ox = np.minimum(np.arange(shape[1]), shape[1] - np.arange(shape[1])) * h
        kernel = np.exp(-(ox[None, :] ** 2 + oy[:, None] ** 2) / (2 * s * s))
        spectrum = (
            np.fft.fft2(white) * np.fft.fft2(kernel) * (rms / math.sqrt(float(np.sum(kernel**2))))
        )
        KX, KY = np.meshgrid(
            2 * np.pi * np.fft.fftfreq(shape[1], d=h), 2 * np.pi * np.fft.fftfreq(shape[0], d=h)
        )
        fields = [
            np.fft.ifft2(spectrum * factor).real for factor in (1.0, 1j * KX, 1j * KY, -KX * KY)
        ]
        inner = (slice(pad, pad + ny), slice(pad, pad + nx))
        return Samples(*(f[inner] for f in fields))


def read_grid(path: str, array: str | None = None) -> tuple[np.ndarray, bool]:
    """The samples of a grid file (ny, nx), row 0 at the lowest y, and whether it is an image.

    An image holds grey levels 0…1 rather than an array of energies. Raises ValueError saying what
    is wrong with the file (missing, unreadable, not 2-D, smaller than 4×4, not finite).
    """
    file = Path(path)
    if not file.is_file():
        raise ValueError(f"an existing .npy, .npz or image file (no file {file})")
    suffix = file.suffix.lower()
    try:
        if suffix in (".npy", ".npz"):
            data = np.load(io.BytesIO(file.read_bytes()), allow_pickle=False)
            if suffix == ".npz":
                names = list(data.files)
                name = array or (names[0] if len(names) == 1 else None)
                if name not in names:
                    raise ValueError(
                        f"an .npz with one array, or array = the name of one of {names}"
                    )
                data = data[name]
            values, image = np.asarray(data, dtype=float), False
        else:
            import matplotlib.image

            values = np.asarray(matplotlib.image.imread(file), dtype=float)
            if values.ndim == 3:  # colour or alpha: the mean of the colour channels
                values = values[..., :3].mean(axis=2)
            if values.size and values.max() > 1:
                values = values / 255.0
            values, image = values[::-1], True  # image rows run top to bottom
    except (OSError, SyntaxError, TypeError, EOFError, KeyError, zipfile.BadZipFile) as err:
        # numpy's and Pillow's read errors: an empty, truncated or damaged file
        why = str(err) or ("the file is empty" if isinstance(err, EOFError) else type(err).__name__)
        raise ValueError(f"a readable .npy, .npz or image file ({why})") from None
    if values.ndim != 2 or min(values.shape) < 4:
        raise ValueError(
            f"a 2-D array of at least 4×4 samples, rows along y (the file holds "
            f"shape {values.shape})"
        )
    if not np.all(np.isfinite(values)):
        raise ValueError("finite values only (the file holds NaN or inf)")
    return values, image


class GridFile(_Kind):
    """A landscape measured or computed elsewhere (e.g. a micromagnetic energy map), from a file.

    ``path`` holds a .npy/.npz array of energies (rows along y, J or k_BT per ``unit``), or a
    greyscale image whose grey level 0…1 is scaled by ``amplitude`` (J) or ``amplitude_kT``.
    ``spacing`` [m] is the distance between samples, ``origin`` [m] the position of the first
    (lower-left) sample. Fitted with a bicubic spline (scipy) and sampled, with its derivatives, at
    the engine's nodes; it must cover the whole device. The file is read and checked when the
    potential is validated; a relative ``path`` in a TOML configuration is taken relative to the
    configuration's folder.
    """

    kind: Literal["grid"] = "grid"
    array: str | None = None  # the array's name inside an .npz (default: its only array)
    path: str
    spacing: Length
    origin: Point = (0.0, 0.0)
    unit: Literal["J", "kT"] = "J"
    amplitude: Energy | None = None
    amplitude_kT: Energy | None = None

    @field_validator("path")
    @classmethod
    def _readable(cls, path: str, info: ValidationInfo) -> str:
        read_grid(path, info.data.get("array"))
        return path

    @model_validator(mode="after")
    def _scale(self):
        image = Path(self.path).suffix.lower() not in (".npy", ".npz")
        if image and (self.amplitude is None) == (self.amplitude_kT is None):
            raise ValueError(
                "an image needs exactly one of amplitude (J) or amplitude_kT "
                "(k_BT) to scale its grey levels"
            )
        return self

    def values(self, kt: float) -> np.ndarray:
        """The energies [pN·nm] on the file's grid (ny, nx), row 0 at the lowest y."""
        from skygas.core.errors import InputError

        values, image = read_grid(self.path, self.array)
        if image:
            return values * _energy(self.amplitude, self.amplitude_kT, kt, "amplitude")
        if self.unit == "kT" and kt <= 0:
            raise InputError(
                "unit", "kT", 'a temperature > 0 (or unit = "J"): k_BT is zero at T = 0'
            )
        return values * (kt if self.unit == "kT" else units.J_TO_PN_NM)

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm), from the spline.

        Raises :class:`~skygas.core.errors.InputError` if the file's samples do not cover the nodes.
        """
        from scipy.interpolate import RectBivariateSpline

        from skygas.core.errors import InputError

        values = self.values(ctx.kt)
        h = self.spacing * units.M_TO_NM
        ys = self.origin[1] * units.M_TO_NM + h * np.arange(values.shape[0])
        xs = self.origin[0] * units.M_TO_NM + h * np.arange(values.shape[1])
        if (
            ctx.x.min() < xs[0] - 1e-9
            or ctx.x.max() > xs[-1] + 1e-9
            or ctx.y.min() < ys[0] - 1e-9
            or ctx.y.max() > ys[-1] + 1e-9
        ):
            need = [ctx.x.min() * 1e-9, ctx.y.min() * 1e-9, ctx.x.max() * 1e-9, ctx.y.max() * 1e-9]
            have = [xs[0] * 1e-9, ys[0] * 1e-9, xs[-1] * 1e-9, ys[-1] * 1e-9]
            raise InputError(
                "path",
                self.path,
                f"samples covering the device's grid, x0 y0 x1 y1 = "
                f"{np.round(need, 12).tolist()} m (the file covers "
                f"{np.round(have, 12).tolist()} m; check spacing and origin)",
            )
        # the spline's first axis is y: ev(y, x, dx=order in y, dy=order in x)
        spline = RectBivariateSpline(ys, xs, values, kx=3, ky=3)
        rows, cols = ctx.y.ravel(), ctx.x.ravel()
        parts = [
            spline.ev(rows, cols, dx=order_y, dy=order_x).reshape(ctx.x.shape)
            for order_x, order_y in ((0, 0), (1, 0), (0, 1), (1, 1))
        ]
        return Samples(*parts)


#: A measured map blends into its statistics over this many correlation lengths by default.
BLEND_CORRELATION_LENGTHS = 3.0


class MeasuredMap(_Kind):
    """A landscape measured where a film was sampled, and random of its statistics elsewhere.

    What ``skygas infer`` writes (docs/inference.md): ``path`` holds a .npy array of U [k_BT]
    (rows along y) on nodes ``spacing`` [m] apart from ``origin`` [m], NaN where the movie did
    not fix it. Where it is finite the landscape is the map (a bicubic spline); elsewhere, and
    beyond the map's extent, a ``disorder`` field of ``rms_kT`` and ``correlation_length`` [m]
    drawn from the run's seed (nothing if ``rms_kT`` is 0). The two are blended by a weight
    that falls from 1 to 0 over about ``blend`` [m] (default: three correlation lengths)
    outside the sampled area, so that no step appears where the map ends, and no bend sharper
    than the landscape's own (which would shorten a run's time step). Derivatives by
    fourth-order central differences on the engine's grid.
    """

    kind: Literal["measured"] = "measured"
    path: str
    spacing: Length
    origin: Point = (0.0, 0.0)
    rms_kT: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.0
    correlation_length: Length
    blend: Length | None = None

    @field_validator("path")
    @classmethod
    def _readable(cls, path: str) -> str:
        values = _map_values(path)
        if not np.any(np.isfinite(values)):
            raise ValueError("a map with at least one finite value (all are NaN)")
        return path

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm)."""
        from scipy import ndimage
        from scipy.interpolate import RectBivariateSpline

        h = float(ctx.x[0, 1] - ctx.x[0, 0])  # nm
        pad = 2
        ny, nx = ctx.x.shape
        xs = ctx.x[0, 0] + h * np.arange(-pad, nx + pad)
        ys = ctx.y[0, 0] + h * np.arange(-pad, ny + pad)
        gx, gy = np.meshgrid(xs, ys)
        values = _map_values(self.path)
        known = np.isfinite(values)
        # the map continued by its nearest known value (the weight hides it), for the spline
        nearest = ndimage.distance_transform_edt(
            ~known, return_distances=False, return_indices=True
        )
        filled = values[tuple(nearest)]
        step = self.spacing * units.M_TO_NM
        mx = self.origin[0] * units.M_TO_NM + step * np.arange(values.shape[1])
        my = self.origin[1] * units.M_TO_NM + step * np.arange(values.shape[0])
        # the weight: 1 where the map is known, falling to 0 over about the blend width outside
        # it, beyond the map's extent too (the mask is padded with unknown nodes first). It is
        # the smoothed mask (½ at the mask's edge) through a smoothstep that is flat to second
        # order at both ends, interpolated by a cubic spline: the weight bends nowhere sharply,
        # so the blend adds no curvature that would shorten a run's time step
        width = (self.blend or BLEND_CORRELATION_LENGTHS * self.correlation_length) * units.M_TO_NM
        pad_nodes = int(np.ceil(2 * width / step)) + 4
        padded = np.pad(known, pad_nodes, constant_values=False).astype(float)
        smooth = ndimage.gaussian_filter(padded, 0.5 * width / step)
        wx = mx[0] + step * np.arange(-pad_nodes, len(mx) + pad_nodes)
        wy = my[0] + step * np.arange(-pad_nodes, len(my) + pad_nodes)
        inside = (gx >= wx[0]) & (gx <= wx[-1]) & (gy >= wy[0]) & (gy <= wy[-1])
        # the map continued by its edge values over the padding: a spline evaluated past its
        # data would extrapolate its last cubic, and bend
        u_map = RectBivariateSpline(wy, wx, np.pad(filled, pad_nodes, mode="edge")).ev(
            gy.ravel(), gx.ravel()
        )
        level = RectBivariateSpline(wy, wx, smooth).ev(gy.ravel(), gx.ravel())
        z = np.clip((level - 0.02) / (0.5 - 0.02), 0.0, 1.0)
        weight = np.where(inside.ravel(), z**3 * (10 - 15 * z + 6 * z * z), 0.0)
        u = (weight * u_map).reshape(gx.shape) * ctx.kt
        if self.rms_kT > 0:
            outside = Disorder(rms_kT=self.rms_kT, correlation_length=self.correlation_length)
            noise = outside.sample(SampleContext(gx, gy, ctx.kt, ctx.seed)).u
            u = u + (1.0 - weight.reshape(gx.shape)) * noise
        ux = fourth_order_derivative(u, h, 1)
        uy = fourth_order_derivative(u, h, 0)
        uxy = fourth_order_derivative(ux, h, 0)
        inner = (slice(pad, -pad), slice(pad, -pad))
        return Samples(u[inner].copy(), ux[pad:-pad, :].copy(), uy[:, pad:-pad].copy(), uxy.copy())


def _map_values(path: str) -> np.ndarray:
    """The 2-D array of a measured map's .npy file (NaN allowed), checked."""
    file = Path(path)
    if not file.is_file() or file.suffix.lower() != ".npy":
        raise ValueError(f"an existing .npy file of U in k_BT (no such file {file})")
    try:
        values = np.asarray(np.load(io.BytesIO(file.read_bytes()), allow_pickle=False), float)
    except (OSError, ValueError, EOFError) as err:
        raise ValueError(f"a readable .npy file ({err or type(err).__name__})") from None
    if values.ndim != 2 or min(values.shape) < 4:
        raise ValueError(f"a 2-D array of at least 4×4 values (the file holds {values.shape})")
    return values


def fourth_order_derivative(f: np.ndarray, spacing: float, axis: int) -> np.ndarray:
    """∂f along ``axis`` by the fourth-order central difference.

    (f(−2) − 8f(−1) + 8f(1) − f(2))/(12 h), on the nodes at least two from the ends (the result
    is 4 shorter along ``axis``).
    """
    n = f.shape[axis]

    def part(lo: int) -> np.ndarray:
        return np.take(f, np.arange(lo, n - 4 + lo), axis=axis)

    return (part(0) - 8 * part(1) + 8 * part(3) - part(4)) / (12 * spacing)


class EdgeStrayField(_Kind):
    """The energy of a skyrmion in the stray field of the film's edges.

    See docs/physics.md §2 and :mod:`skygas.fields.landscape.stray_field`:

        U(r) = μ₀ M_s t ∫_film w(|r' − r|) H_dev(r') dA'

    with ``saturation_magnetization`` M_s [A/m], film ``thickness`` t [m] and the skyrmion's
    deficit w = 1 − m_z (``profile_deficit``, dimensionless) at ``profile_radius`` [m]. The film
    is the device's outline (continued beyond its ports to the edge of the engine's grid, so
    that a port is not an edge). A calibrated material with a ``stray_field`` profile adds this
    term itself when its tabulated wall law is used; listing it by hand is for other uses.

    U is computed on the engine's grid, padded by two nodes, and differentiated by fourth-order
    central differences (U varies on the skyrmion's scale, many nodes wide).
    """

    kind: Literal["edge_stray_field"] = "edge_stray_field"
    saturation_magnetization: Length
    thickness: Length
    profile_radius: tuple[Annotated[float, Field(ge=0, allow_inf_nan=False)], ...]
    profile_deficit: tuple[Annotated[float, Field(ge=0, le=2, allow_inf_nan=False)], ...]

    needs_film: ClassVar[bool] = True

    @model_validator(mode="after")
    def _profile(self):
        r, w = self.profile_radius, self.profile_deficit
        if len(r) < 2 or len(w) != len(r):
            raise ValueError(
                "profile_radius and profile_deficit need the same number (>= 2) of values"
            )
        if r[0] != 0 or any(b <= a for a, b in zip(r, r[1:], strict=False)):
            raise ValueError("profile_radius must increase strictly from 0")
        return self

    def sample(self, ctx: SampleContext) -> Samples:
        """U and its derivatives at the nodes of ``ctx`` (pN·nm, pN, pN/nm).

        Raises :class:`~skygas.core.errors.InputError` without ``ctx.inside`` (a context made by a
        Simulation, which knows the device's outline).
        """
        from skygas.core.errors import InputError

        if ctx.inside is None:
            raise InputError(
                "kind",
                self.kind,
                "a term sampled by a Simulation, which knows "
                "the device's outline (SampleContext.inside)",
            )
        spacing = float(ctx.x[0, 1] - ctx.x[0, 0])  # nm
        film = np.pad(np.asarray(ctx.inside, dtype=float), 2)
        key = (
            hashlib.sha256(film.tobytes()).hexdigest(),
            film.shape,
            spacing,
            self.model_dump_json(),
        )
        u = _STRAY_ENERGY.get(key, lambda: self._energy(film, spacing))
        ux = fourth_order_derivative(u, spacing, 1)
        uy = fourth_order_derivative(u, spacing, 0)
        uxy = fourth_order_derivative(ux, spacing, 0)
        inner = (slice(2, -2), slice(2, -2))
        return Samples(u[inner].copy(), ux[2:-2, :].copy(), uy[:, 2:-2].copy(), uxy.copy())

    def _energy(self, film: np.ndarray, spacing_nm: float) -> np.ndarray:
        """U [pN·nm] at the nodes of the padded film (read-only: it is memoised)."""
        from skygas.core.memo import frozen
        from skygas.fields.landscape.stray_field import stray_field_energy

        u = (
            stray_field_energy(
                film,
                spacing_nm / units.M_TO_NM,
                self.thickness,
                self.saturation_magnetization,
                self.profile_radius,
                self.profile_deficit,
            )
            * units.J_TO_PN_NM
        )
        frozen(u)
        return u


Potential = Annotated[
    Gaussian | Periodic | Band | RandomPinning | Disorder | GridFile | MeasuredMap | EdgeStrayField,
    Field(discriminator="kind"),
]
KINDS: dict[str, type[_Kind]] = {
    "gaussian": Gaussian,
    "periodic": Periodic,
    "band": Band,
    "random_pinning": RandomPinning,
    "disorder": Disorder,
    "grid": GridFile,
    "measured": MeasuredMap,
    "edge_stray_field": EdgeStrayField,
}
# pydantic names the member tried in an error's location: not a field (to_input_error)
register_union_tags(KINDS)
