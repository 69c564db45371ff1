"""Forces from trajectories and fits of the paper's pair and wall laws.

Force extraction (paper, "Skyrmion Interactions"): with no current and no noise the Thiele
equation reads F = Ĝ^α·ẋ with Ĝ^α = G ε + α𝒟k I, ε = [[0, 1], [−1, 0]], k = M_s t_F/γ and
G = −4πQk, the conventions of :func:`skygas.physics.materials.derive_thiele`. Componentwise

    F_x = α𝒟k ẋ + G ẏ,    F_y = −G ẋ + α𝒟k ẏ.

Velocities come from a local least-squares polynomial (Savitzky–Golay) derivative, which
averages out the sub-cell jitter of detected centres; its window sets the smoothing.

Laws (docs/physics.md §2), d in units of the skyrmion diameter d_sk, F₀ the force scale:

- pair:  |F| = F₀ exp[−(a₂d² + a₁d + a₀)/(d + 1)], repulsive along the line of centres;
- wall:  |F| = F₀ exp[−p(d)], p = polyval(b, d) (highest power first), along the inward normal.

Fits: ln(|F|/F₀) is linear in the coefficients (for the pair law after multiplying by d + 1), so
a linear least-squares solution starts a nonlinear least-squares refinement on ln|F| (equal
weight to every sample in relative terms), whose covariance gives the quoted 1σ uncertainties.

Checks (:func:`law_problem`): the engine uses a law from the closest approach it allows
(``MIN_PLACEMENT_SEPARATION`` = 0.5 d_sk) out to its cutoff, where |F| stays below 10⁻³ F₀
(:func:`skygas.physics.forces.cutoff_distance`). A fitted law must there be

- bounded: it decays to zero far away (a₂ > 0; for the wall law a positive leading
  coefficient), and falls below the cutoff fraction within 50 d_sk, as the engine requires;
- decreasing from ``DECREASING_FROM`` = 1 d_sk to the cutoff. Closer than one diameter the laws
  are not valid (paper, "Boundary Effects"), and the paper's own S2 law peaks at 0.85 d_sk, so
  there it need only be finite and positive (which both forms always are).

A pair fit that fails the checks only outside its data (an extrapolation: a narrow range of d
fixes a₂ poorly, and a₂ < 0 makes the force grow without bound) is refitted with the
constraints built in (:func:`fit_pair_law`): a₂ ≥ ``PAIR_A2_FLOOR`` and
p'(1) ∝ 3a₂ + a₁ − a₀ ≥ 0, which with a₂ > 0 makes p(d) = (a₂d² + a₁d + a₀)/(d + 1) increase,
and the force decrease, for all d ≥ 1. A law that rises inside its own data is refused
(:class:`~skygas.core.errors.InputError`): the samples do not show a decaying repulsion. A law
that no constrained law repairs (or a wall polynomial that fails the checks outside its data)
raises :class:`UnfixedLawError`, an :class:`~skygas.core.errors.InputError` that says the samples
do not fix the law *outside their range*; :func:`skygas.micromag.fit_trajectories` then keeps
what the data do fix, the law tabulated over the measured range (:func:`tabulate_law`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, signal

from skygas.core.errors import InputError
from skygas.physics.forces import law_coefficient_names, law_formula

#: Smallest distance [d_sk] from which a fitted law must decrease (see the module docstring).
DECREASING_FROM = 1.0
#: Lower bound of a₂ in a constrained pair fit (a small positive number: the force decays).
PAIR_A2_FLOOR = 0.01


def pair_law_magnitude(d, pair_law) -> np.ndarray:
    """exp[−(a₂d² + a₁d + a₀)/(d + 1)] for ``pair_law`` = [a₂, a₁, a₀] (dimensionless)."""
    a2, a1, a0 = pair_law
    d = np.asarray(d, dtype=np.float64)
    return np.exp(-(a2 * d * d + a1 * d + a0) / (d + 1.0))


def wall_law_magnitude(d, wall_law) -> np.ndarray:
    """exp[−polyval(b, d)] for ``wall_law`` b, highest power first (dimensionless)."""
    return np.exp(-np.polyval(np.asarray(wall_law, dtype=np.float64), np.asarray(d, float)))


@dataclass(frozen=True)
class LineBoundary:
    """A straight wall through ``point`` [m]; the film lies on the side of ``inward_normal``."""

    point: tuple[float, float]
    inward_normal: tuple[float, float]

    def distance_and_normal(self, positions) -> tuple[np.ndarray, np.ndarray]:
        """Distance to the wall [m] and the unit inward normal, for positions (n, 2) [m]."""
        normal = np.asarray(self.inward_normal, float) / np.hypot(*self.inward_normal)
        positions = np.atleast_2d(positions)
        dist = (positions - np.asarray(self.point)) @ normal
        return dist, np.broadcast_to(normal, positions.shape)


@dataclass(frozen=True)
class DiskBoundary:
    """A disk-shaped film of ``radius`` [m] around ``centre`` [m]."""

    centre: tuple[float, float]
    radius: float

    def distance_and_normal(self, positions) -> tuple[np.ndarray, np.ndarray]:
        """Distance to the rim [m] and the unit inward normal (towards the centre)."""
        offset = np.atleast_2d(positions) - np.asarray(self.centre)
        r = np.linalg.norm(offset, axis=-1)
        normal = -offset / np.where(r > 0, r, 1.0)[:, None]
        return self.radius - r, normal


def disk_from_mask(magnetic: np.ndarray, x: np.ndarray, y: np.ndarray) -> DiskBoundary:
    """The disk of a film mask (ny, nx) on cell centres ``x``, ``y`` [m].

    Its centroid and the radius of equal area, √(A/π), which is exact up to the staircase of the
    cells.
    """
    magnetic = np.asarray(magnetic, bool)
    if magnetic.all():
        raise InputError(
            "boundary",
            "no empty cells",
            "a disk geometry (cells outside the disk written as m = 0) for a wall fit",
        )
    yy, xx = np.meshgrid(y, x, indexing="ij")
    area = magnetic.sum() * abs(x[1] - x[0]) * abs(y[1] - y[0])
    return DiskBoundary(
        (float(xx[magnetic].mean()), float(yy[magnetic].mean())), math.sqrt(area / math.pi)
    )


def velocities(times, positions, window: int = 9, order: int = 3) -> np.ndarray:
    """dx/dt [m/s] of positions (n, 2) [m] at ``times`` [s] by a Savitzky–Golay derivative.

    ``window`` (odd, samples) sets the smoothing; the sampling must be uniform (as snapshots
    written at a fixed interval are). Fewer samples than the window fall back to a polynomial of
    the whole track.
    """
    times = np.asarray(times, dtype=np.float64)
    positions = np.asarray(positions, dtype=np.float64)
    if times.size < 3:
        raise InputError("trajectory length", times.size, "at least 3 samples for a velocity")
    steps = np.diff(times)
    if np.any(steps <= 0) or np.ptp(steps) > 1e-6 * steps.mean():
        raise InputError("times", "non-uniform", "uniformly spaced, increasing snapshot times")
    if window % 2 == 0 or window <= order:
        raise InputError("window", window, f"an odd number of samples > order = {order}")
    window = min(window, times.size if times.size % 2 else times.size - 1)
    order = min(order, window - 1)
    return signal.savgol_filter(
        positions, window, order, deriv=1, delta=steps.mean(), axis=0, mode="interp"
    )


def thiele_forces(velocity, gyrocoupling: float, friction: float) -> np.ndarray:
    """F = (G ε + α𝒟k I)·ẋ [N] for velocities (n, 2) [m/s]; G, α𝒟k in kg/s."""
    v = np.asarray(velocity, dtype=np.float64)
    return np.stack(
        [
            friction * v[..., 0] + gyrocoupling * v[..., 1],
            -gyrocoupling * v[..., 0] + friction * v[..., 1],
        ],
        axis=-1,
    )


def pair_samples(pos_a, force_a, pos_b, force_b, diameter: float):
    """Distances d (units of ``diameter``) and repulsive pair-force magnitudes [N].

    Each skyrmion's force is projected on the unit vector pointing away from the other one; the
    two estimates (equal by Newton's third law for an isolated pair) are averaged.
    """
    sep = np.asarray(pos_a) - np.asarray(pos_b)
    dist = np.linalg.norm(sep, axis=-1)
    unit = sep / dist[:, None]
    along = 0.5 * (np.einsum("ij,ij->i", force_a, unit) - np.einsum("ij,ij->i", force_b, unit))
    return dist / diameter, along


def wall_samples(positions, forces, boundary, diameter: float):
    """Distances to the wall d (units of ``diameter``) and inward force components [N]."""
    dist, normal = boundary.distance_and_normal(positions)
    return dist / diameter, np.einsum("ij,ij->i", np.asarray(forces), normal)


@dataclass(frozen=True)
class LawFit:
    """A fitted force law.

    Attributes: ``law`` ("pair" or "wall"); ``coefficients`` ([a₂, a₁, a₀] or b, highest power
    first) and their 1σ ``uncertainties``; ``force_scale`` F₀ [N]; ``n_points`` used;
    ``distance_range`` (d_min, d_max) in diameters; ``rms_log_residual`` of ln|F|;
    ``n_rejected`` samples left out because their force was not repulsive (F ≤ 0); ``note``
    says why a constrained law replaced the unconstrained fit (empty if it did not).
    """

    law: str
    coefficients: tuple[float, ...]
    uncertainties: tuple[float, ...]
    force_scale: float
    n_points: int
    distance_range: tuple[float, float]
    rms_log_residual: float
    n_rejected: int = 0
    covariance: list = field(default_factory=list, repr=False)
    note: str = ""

    @property
    def formula(self) -> str:
        """The law's functional form, with its coefficients' names (d in skyrmion diameters)."""
        return law_formula(self.law, len(self.coefficients))

    @property
    def coefficient_names(self) -> tuple[str, ...]:
        """The coefficients' names, in the order of :attr:`coefficients` (all dimensionless)."""
        return law_coefficient_names(self.law, len(self.coefficients))

    def describe(self) -> str:
        """The law with its named values: form, F₀ [N], each coefficient ± its 1σ uncertainty.

        For example ``|F|(d) = F₀·exp[−(a₂d² + a₁d + a₀)/(d + 1)], d in skyrmion diameters:
        F₀ = 3.2e-12 N, a₂ = 0.52 ± 0.03, a₁ = 1.9 ± 0.1, a₀ = −0.4 ± 0.2 (dimensionless)``.
        """
        values = ", ".join(
            f"{name} = {c:.5g} ± {u:.2g}" if math.isfinite(u) else f"{name} = {c:.5g}"
            for name, c, u in zip(
                self.coefficient_names, self.coefficients, self.uncertainties, strict=True
            )
        )
        return (
            f"{self.formula}, d in skyrmion diameters: F₀ = {self.force_scale:.4g} N, {values} "
            "(dimensionless)"
        )

    def magnitude(self, d) -> np.ndarray:
        """The fitted |F| [N] at distances d (diameters)."""
        shape = pair_law_magnitude if self.law == "pair" else wall_law_magnitude
        return self.force_scale * shape(d, self.coefficients)

    def as_record(self) -> dict:
        """The fit as a JSON-able dict (``fit.json``), with the range the engine uses it over."""
        return {
            "law": self.law,
            "formula": self.formula,
            "coefficient_names": list(self.coefficient_names),
            "coefficients": list(self.coefficients),
            "uncertainties": list(self.uncertainties),
            "force_scale_N": self.force_scale,
            "n_points": self.n_points,
            "distance_range": list(self.distance_range),
            "rms_log_residual": self.rms_log_residual,
            "n_rejected": self.n_rejected,
            "covariance": self.covariance,
            "note": self.note,
            "engine_range": list(engine_range(self.law, self.coefficients)),
        }


class UnfixedLawError(InputError):
    """The samples fit no law the engine accepts, for want of data outside their range.

    Not because of the data inside it: ``fit`` is the unconstrained :class:`LawFit`, ``why`` what
    fails (``"the fit grows without bound far away …"``), ``unfixed`` what the samples do not fix
    (``"how the force decays beyond 2.25 d_sk"``), ``remedy`` what to record instead.
    """

    def __init__(self, fit: LawFit, why: str, unfixed: str, remedy: str):
        self.fit, self.why, self.unfixed, self.remedy = fit, why, unfixed, remedy
        lo, hi = fit.distance_range
        super().__init__(
            f"{fit.law}_law",
            _rounded(fit.coefficients),
            f"a force that decays with distance: {why}, so the samples do not "
            f"fix {unfixed} (data: d = {lo:.2f}–{hi:.2f} d_sk)",
            remedy,
        )


@dataclass(frozen=True)
class LawTable:
    """A force law tabulated over the measured distances only.

    The samples sorted by distance and cut into bins of (nearly) equal counts.

    Per bin: ``d_low``, ``d_high`` (the extreme sample distances) and ``distance`` (the median)
    in d_sk; ``force`` the median force [N] (signed: the repulsive component, so that noise
    around zero does not bias it), ``force_q25``, ``force_q75`` its interquartile range [N] and
    ``count`` the samples. ``diameter`` d_sk [m] and ``force_scale`` F₀ [N] convert the units.
    """

    law: str
    diameter: float
    force_scale: float
    d_low: np.ndarray
    d_high: np.ndarray
    distance: np.ndarray
    force: np.ndarray
    force_q25: np.ndarray
    force_q75: np.ndarray
    count: np.ndarray

    COLUMNS = (
        "distance_m",
        "distance_diameters",
        "force_N",
        "force_over_F0",
        "n_samples",
        "force_q25_N",
        "force_q75_N",
        "d_low_diameters",
        "d_high_diameters",
    )

    def rows(self) -> list[dict]:
        """One dict per bin, keyed by :attr:`COLUMNS` (SI units, d also in d_sk)."""
        return [
            dict(
                zip(
                    self.COLUMNS,
                    (
                        float(d) * self.diameter,
                        float(d),
                        float(f),
                        float(f) / self.force_scale,
                        int(n),
                        float(lo_f),
                        float(hi_f),
                        float(lo),
                        float(hi),
                    ),
                    strict=True,
                )
            )
            for d, f, n, lo_f, hi_f, lo, hi in zip(
                self.distance,
                self.force,
                self.count,
                self.force_q25,
                self.force_q75,
                self.d_low,
                self.d_high,
                strict=True,
            )
        ]

    @property
    def distance_range(self) -> tuple[float, float]:
        """The measured range (d_min, d_max) in d_sk."""
        return float(self.d_low.min()), float(self.d_high.max())

    def as_record(self) -> dict:
        """The table as a JSON-able dict, its rows as :meth:`rows` gives them."""
        return {
            "law": self.law,
            "skyrmion_diameter_m": self.diameter,
            "force_scale_N": self.force_scale,
            "distance_range": list(self.distance_range),
            "n_samples": int(self.count.sum()),
            "rows": self.rows(),
        }


def tabulate_law(
    law: str, d, force, diameter: float, force_scale: float, bins: int | None = None
) -> LawTable:
    """The samples (d [d_sk], force [N]) as a :class:`LawTable` of bins of equal counts.

    A monotonic law maps the median distance of a bin to its median force, so a table of
    exact samples lies on the law whatever the bins' widths (exactly for odd counts; for even
    ones, the median is the mean of two neighbouring samples).

    Parameters
    ----------
    law : str
        "pair" or "wall".
    d : array_like
        Distances [d_sk]; non-finite samples are left out.
    force : array_like
        Forces [N], one per distance (the repulsive component).
    diameter : float
        d_sk [m], > 0.
    force_scale : float
        F₀ [N], > 0.
    bins : int, optional
        The number of bins (default: ⌈√n⌉ for n samples, at most 20: as many bins as samples per
        bin).

    Returns
    -------
    LawTable

    Raises
    ------
    InputError
        If ``diameter`` or ``force_scale`` is not > 0, no sample is finite, or ``bins`` is not an
        integer ≥ 1.
    """
    if not (diameter > 0 and force_scale > 0):
        raise InputError("diameter, force_scale", (diameter, force_scale), "values > 0 (m, N)")
    d = np.asarray(d, dtype=np.float64).ravel()
    force = np.asarray(force, dtype=np.float64).ravel()
    keep = np.isfinite(d) & np.isfinite(force)
    if not keep.any():
        raise InputError("force samples", 0, "at least one finite sample to tabulate")
    d, force = d[keep], force[keep]
    if bins is None:
        bins = min(20, math.ceil(math.sqrt(d.size)))
    if not (isinstance(bins, int) and bins >= 1):
        raise InputError("table bins", bins, "an integer >= 1")
    groups = np.array_split(np.argsort(d, kind="stable"), min(bins, d.size))

    def per_bin(values, statistic):
        return np.array([statistic(values[g]) for g in groups])

    return LawTable(
        law,
        float(diameter),
        float(force_scale),
        per_bin(d, np.min),
        per_bin(d, np.max),
        per_bin(d, np.median),
        per_bin(force, np.median),
        per_bin(force, lambda v: np.percentile(v, 25)),
        per_bin(force, lambda v: np.percentile(v, 75)),
        np.array([g.size for g in groups]),
    )


def _clean(d, force, force_scale: float, need: int):
    if not force_scale > 0:
        raise InputError("force_scale", force_scale, "a force > 0 in newtons")
    d = np.asarray(d, dtype=np.float64).ravel()
    force = np.asarray(force, dtype=np.float64).ravel()
    keep = np.isfinite(d) & np.isfinite(force) & (force > 0)
    if keep.sum() < need:
        raise InputError("force samples", int(keep.sum()), f"at least {need} repulsive samples")
    return d[keep], np.log(force[keep] / force_scale), int((~keep).sum())


def _finish(law, model, d, y, start, force_scale, rejected) -> LawFit:
    try:
        with warnings.catch_warnings():  # exact samples: no covariance, the fit is still right
            warnings.simplefilter("ignore", optimize.OptimizeWarning)
            params, cov = optimize.curve_fit(model, d, y, p0=start, method="lm")
    except RuntimeError:  # keep the linear solution
        params, cov = start, np.full((len(start), len(start)), np.nan)
    residual = y - model(d, *params)
    return LawFit(
        law,
        tuple(map(float, params)),
        tuple(map(float, np.sqrt(np.diag(cov)))),
        float(force_scale),
        int(d.size),
        (float(d.min()), float(d.max())),
        float(np.sqrt(np.mean(residual**2))),
        rejected,
        np.asarray(cov).tolist(),
    )


def _pair_model(x, a2, a1, a0):
    return -(a2 * x * x + a1 * x + a0) / (x + 1.0)


def fit_pair_law(d, force, force_scale: float, check: bool = True) -> LawFit:
    """Fit [a₂, a₁, a₀] of |F| = F₀ exp[−(a₂d² + a₁d + a₀)/(d+1)] to samples (d, |F| [N]).

    With ``check``, a law that fails :func:`law_problem` outside the data is refitted with the
    constraints built in (``note`` says so); one that rises inside the data raises
    :class:`InputError`, one that no constrained law repairs :class:`UnfixedLawError` (see the
    module docstring).
    """
    d, y, rejected = _clean(d, force, force_scale, need=4)
    # (d + 1) ln(F/F₀) = −a₂d² − a₁d − a₀ is linear in the coefficients.
    design = -np.stack([d * d, d, np.ones_like(d)], axis=-1)
    start = np.linalg.lstsq(design, (d + 1.0) * y, rcond=None)[0]
    fit = _finish("pair", _pair_model, d, y, start, force_scale, rejected)
    reason = law_problem("pair", fit.coefficients) if check else None
    if reason is None:
        return fit
    _refuse_if_rising_in_data(fit)
    constrained = _constrained_pair_fit(d, y, fit, reason, rejected)
    problem = law_problem("pair", constrained.coefficients)
    if problem is not None:
        raise UnfixedLawError(
            fit,
            f"the fit {reason} and even the best decaying law {problem}",
            f"how the force decays beyond {fit.distance_range[1]:.2f} d_sk",
            "record snapshots until the skyrmions are farther apart",
        )
    return constrained


def _constrained_pair_fit(d, y, free: LawFit, reason: str, rejected: int) -> LawFit:
    """The least-squares pair law with a₂ ≥ PAIR_A2_FLOOR and c = 3a₂ + a₁ − a₀ ≥ 0.

    Parameters x = (a₂, c, a₀), so that the constraints are simple bounds;
    a = A·x with a₁ = c + a₀ − 3a₂.
    """
    to_law = np.array([[1.0, 0.0, 0.0], [-3.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    a2, a1, a0 = free.coefficients
    x0 = [max(a2, 2 * PAIR_A2_FLOOR), max(3 * a2 + a1 - a0, 1e-3), a0]

    def residual(x):
        return _pair_model(d, *(to_law @ x)) - y

    solution = optimize.least_squares(
        residual, x0, bounds=([PAIR_A2_FLOOR, 0.0, -np.inf], np.inf), x_scale="jac"
    )
    coefficients = to_law @ solution.x
    dof = max(d.size - 3, 1)
    try:
        cov_x = np.linalg.inv(solution.jac.T @ solution.jac) * (2 * solution.cost / dof)
        cov = to_law @ cov_x @ to_law.T
    except np.linalg.LinAlgError:
        cov = np.full((3, 3), np.nan)
    rms = float(np.sqrt(np.mean(residual(solution.x) ** 2)))
    note = (
        f"pair law fitted with a₂ ≥ {PAIR_A2_FLOOR} and decreasing from "
        f"{DECREASING_FROM:g} d_sk on: the unconstrained fit {_named('pair', free.coefficients)} "
        f"{reason} (outside the data, d = {free.distance_range[0]:.2f}–"
        f"{free.distance_range[1]:.2f} d_sk); rms ln-residual "
        f"{free.rms_log_residual:.3g} → {rms:.3g}"
    )
    return LawFit(
        "pair",
        tuple(map(float, coefficients)),
        tuple(map(float, np.sqrt(np.abs(np.diag(cov))))),
        free.force_scale,
        int(d.size),
        free.distance_range,
        rms,
        rejected,
        np.asarray(cov).tolist(),
        note,
    )


def fit_wall_law(d, force, force_scale: float, degree: int = 5, check: bool = True) -> LawFit:
    """Fit b (degree ``degree``, highest power first) of |F| = F₀ exp[−polyval(b, d)].

    With ``check``, a law that rises inside its data raises :class:`InputError`, one that
    fails :func:`law_problem` only outside them :class:`UnfixedLawError` (a polynomial has no
    constrained refit here: a lower degree, or data over more of the range, is the remedy).
    """
    if not (isinstance(degree, int) and degree >= 1):
        raise InputError("degree", degree, "an integer >= 1")
    d, y, rejected = _clean(d, force, force_scale, need=degree + 3)
    start = np.polyfit(d, -y, degree)

    def model(x, *b):
        return -np.polyval(b, x)

    fit = _finish("wall", model, d, y, start, force_scale, rejected)
    problem = law_problem("wall", fit.coefficients) if check else None
    if problem is not None:
        _refuse_if_rising_in_data(fit)
        raise UnfixedLawError(
            fit,
            f"the fit {problem}",
            "the force beyond them, where the engine uses the law too",
            f"refit with a lower --wall-degree (now {degree}) or with snapshots that "
            "cover more of the range",
        )
    return fit


def _rounded(coefficients) -> list[float]:
    return [float(f"{c:.4g}") for c in coefficients]


def _named(law: str, coefficients) -> str:
    """``(a₂, a₁, a₀) = (…)``: the coefficients with their names (4 significant digits)."""
    names = ", ".join(law_coefficient_names(law, len(coefficients)))
    return f"({names}) = ({', '.join(f'{c:.4g}' for c in coefficients)})"


def _refusal(fit: LawFit, why: str, remedy: str) -> InputError:
    """The one-line refusal of a fitted law: what is wrong, the data's range, what to do."""
    lo, hi = fit.distance_range
    return InputError(
        f"{fit.law}_law",
        _rounded(fit.coefficients),
        f"a force that decays with distance: {why} (data: d = {lo:.2f}–{hi:.2f} d_sk); {remedy}",
    )


def _magnitude(law: str, coefficients):
    shape = pair_law_magnitude if law == "pair" else wall_law_magnitude
    return lambda d: shape(d, coefficients)


def engine_range(law: str, coefficients) -> tuple[float, float]:
    """(closest approach, cutoff) in d_sk: the distances at which the engine uses the law.

    The cutoff is NaN where the law does not fall below the cutoff fraction within 50 d_sk.
    """
    from skygas.engine import MIN_PLACEMENT_SEPARATION  # imports numba: only when fitting
    from skygas.physics.forces import cutoff_distance

    try:
        cutoff = cutoff_distance(_magnitude(law, coefficients))
    except InputError:
        cutoff = math.nan
    return float(MIN_PLACEMENT_SEPARATION), float(cutoff)


def _rising(law: str, coefficients, lo: float, hi: float) -> tuple[float, float] | None:
    """The first and last distance in [lo, hi] (d_sk) where the law's force rises, or None."""
    if not hi > lo:
        return None
    d = np.linspace(lo, hi, 4001)
    up = np.flatnonzero(np.diff(_magnitude(law, coefficients)(d)) > 0)
    return None if up.size == 0 else (float(d[up[0]]), float(d[up[-1] + 1]))


def law_problem(law: str, coefficients) -> str | None:
    """Why the engine cannot use this law as a decaying force (None if it can).

    Checks, in d_sk (see the module docstring): the leading coefficient is positive (the force
    decays to zero far away); the force falls below the engine's cutoff fraction within 50 d_sk;
    it decreases from ``DECREASING_FROM`` (or the closest approach, if larger) to the cutoff.
    """
    from skygas.physics.forces import DEFAULT_CUTOFF_FRACTION

    name = "a₂" if law == "pair" else "the leading coefficient"
    if not coefficients[0] > 0:
        if coefficients[0] < 0:
            return f"grows without bound far away ({name} = {coefficients[0]:.4g} < 0)"
        return f"does not decay to zero far away ({name} = 0)"
    closest, cutoff = engine_range(law, coefficients)
    if not math.isfinite(cutoff):
        return f"stays above {DEFAULT_CUTOFF_FRACTION:g} F₀ beyond 50 d_sk"
    rising = _rising(law, coefficients, max(closest, DECREASING_FROM), cutoff)
    if rising is not None:
        return f"rises with distance at d = {rising[0]:.2f}–{rising[1]:.2f} d_sk"
    return None


def _refuse_if_rising_in_data(fit: LawFit) -> None:
    """Refuse a law whose force rises with distance inside the data's own range.

    There the samples themselves do not show a decaying repulsion, and no constraint can repair
    that.
    """
    lo, hi = fit.distance_range
    rising = _rising(fit.law, fit.coefficients, max(lo, DECREASING_FROM), hi)
    if rising is not None:
        raise _refusal(
            fit,
            f"the fit rises at d = {rising[0]:.2f}–{rising[1]:.2f} d_sk, inside "
            "the data, so the samples do not show a decaying repulsion",
            "check that the snapshots hold one relaxing pair (no third skyrmion) "
            "or one skyrmion near the wall",
        )
