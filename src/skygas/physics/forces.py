"""Force laws: small pure functions of a distance, and their tabulation for the engine.

All laws are dimensionless: they take a distance ``d`` in units of the skyrmion diameter d_sk
and return the force magnitude in units of F₀ (docs/physics.md §2). The engine multiplies by F₀.

- :func:`paper_pair_force`: |F| = exp[−(a₂d² + a₁d + a₀)/(d + 1)] (paper eq. "interparticle",
  coefficient order of the Appendix C table), repulsive along the line of centres.
- :func:`paper_wall_force`: |F| = exp[−p(d)], p a polynomial with the highest power first
  (paper eq. "boundary", Methods' b vector), along the inward wall normal.
- :func:`law_formula` / :func:`law_coefficient_names`: the two paper laws written out with their
  coefficients' names, for what a fit prints and draws.
- :func:`lin_reichhardt_pair_force`: |F| = A·K₁(d/λ) (Lin, Reichhardt, Batista & Saxena,
  PRB 87, 214419 (2013)), an alternative pair law.
- :func:`tabulated_force` / :func:`tabulated_law`: a calibrated model's table of |F| [N] against
  the distance [m] (centre–centre for the pair law, centre to the nearest wall for the wall law;
  :class:`skygas.physics.materials.ForceTableSpec`). The law is the PCHIP interpolant
  (``scipy.interpolate.PchipInterpolator``: monotone between nodes, no overshoot, so a table of
  non-negative forces stays non-negative) of the table at the physical distance d·d_sk, divided
  by F₀. Below the first distance it is held at the first force; beyond the last distance it is
  exactly 0. The table is in SI, so changing d_sk or F₀ does not change the physical law.

Cutoff
------
A law is cut at the distance beyond which its force stays below ``cutoff_fraction`` × F₀
(default 10⁻³: for set S2 the pair law reaches it at 5.07 d_sk ≈ 194 nm and the wall law at
6.70 d_sk ≈ 256 nm). The force is set to zero beyond the cutoff; the jump there is at most
``cutoff_fraction`` × F₀, far below the thermal force scale at 300 K.

Validity
--------
The paper warns that both laws are not valid below about one diameter (annihilation is the
physical outcome there). The wall law is evaluated at d = 0 for centres on or beyond the wall,
so the force stays finite if a skyrmion is pushed onto the wall.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special
from scipy.interpolate import PchipInterpolator

from skygas.core.errors import InputError

#: Default fraction of F₀ below which a force law is cut to zero.
DEFAULT_CUTOFF_FRACTION = 1e-3


def paper_pair_force(d, a2: float, a1: float, a0: float):
    """Paper's skyrmion–skyrmion law, |F|/F₀ = exp[−(a₂d² + a₁d + a₀)/(d + 1)].

    ``d`` is the centre distance in skyrmion diameters (scalar or array).
    """
    d = np.asarray(d, dtype=float)
    return np.exp(-(a2 * d * d + a1 * d + a0) / (d + 1.0))


def paper_wall_force(d, coefficients):
    """Paper's skyrmion–wall law, |F|/F₀ = exp[−p(d)], p(d) = polyval(coefficients, d).

    ``coefficients`` are highest power first; ``d`` (skyrmion diameters) is clamped at 0.
    """
    d = np.maximum(np.asarray(d, dtype=float), 0.0)
    return np.exp(-np.polyval(np.asarray(coefficients, dtype=float), d))


_SUBSCRIPTS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
_SUPERSCRIPTS = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")


def law_coefficient_names(law: str, count: int) -> tuple[str, ...]:
    """Names of a paper law's ``count`` coefficients, highest power first.

    ``law`` is "pair" or "wall". The pair law's are a₂, a₁, a₀; the wall polynomial's of degree n
    are bₙ, …, b₁, b₀.
    """
    letter = "a" if law == "pair" else "b"
    return tuple(f"{letter}{str(k).translate(_SUBSCRIPTS)}" for k in range(count - 1, -1, -1))


def law_formula(law: str, count: int) -> str:
    """The functional form of a paper law with ``count`` coefficients, as text.

    ``|F|(d) = F₀·exp[−(a₂d² + a₁d + a₀)/(d + 1)]`` for the pair law, ``|F|(d) =
    F₀·exp[−(b₂d² + b₁d + b₀)]`` for a wall polynomial of degree 2; d in skyrmion diameters.
    """
    names = law_coefficient_names(law, count)
    terms = []
    for name, power in zip(names, range(count - 1, -1, -1), strict=True):
        terms.append(
            name
            if power == 0
            else f"{name}d" + ("" if power == 1 else str(power).translate(_SUPERSCRIPTS))
        )
    poly = " + ".join(terms)
    if law == "pair":
        return f"|F|(d) = F₀·exp[−({poly})/(d + 1)]"
    return f"|F|(d) = F₀·exp[−({poly})]"


def lin_reichhardt_pair_force(d, amplitude: float = 1.0, decay_length: float = 0.5):
    """Lin–Reichhardt pair law, |F|/F₀ = A·K₁(d/λ), λ in skyrmion diameters.

    K₁ diverges as λ/d at contact; the law is tabulated from ``d ≥ 0.05 λ`` (held constant
    below), which only matters for overlapping skyrmions that the model does not describe.
    """
    d = np.maximum(np.asarray(d, dtype=float), 0.05 * decay_length)
    return amplitude * special.k1(d / decay_length)


def tabulated_law(distance, force, skyrmion_diameter: float, force_scale: float):
    """A tabulated force as a law: a callable of d (skyrmion diameters) returning |F|/F₀.

    ``distance`` [m] (strictly increasing, ≥ 0) and ``force`` [N] are the table; the law is the
    PCHIP interpolant of the table at r = d·``skyrmion_diameter`` [m], divided by
    ``force_scale`` F₀ [N]; held at ``force[0]`` for r below ``distance[0]`` and 0 for r beyond
    ``distance[-1]``. The interpolation runs in nm and pN, where the numbers are of order one.
    Raises :class:`InputError` unless the table has at least two strictly increasing distances with
    one force each.
    """
    r_nm = np.asarray(distance, dtype=float) * 1e9
    f_pn = np.asarray(force, dtype=float) * 1e12
    if r_nm.ndim != 1 or len(r_nm) < 2 or r_nm.shape != f_pn.shape or np.any(np.diff(r_nm) <= 0):
        raise InputError(
            "force table",
            list(distance),
            "at least two strictly increasing distances with one force each",
        )
    interpolant = PchipInterpolator(r_nm, f_pn, extrapolate=False)
    d_sk_nm, f0_pn = skyrmion_diameter * 1e9, force_scale * 1e12
    first, last = r_nm[0], r_nm[-1]

    def law(d):
        r = np.asarray(d, dtype=float) * d_sk_nm
        inside = interpolant(np.clip(r, first, last))
        out = np.where(r < first, f_pn[0], np.where(r > last, 0.0, inside))
        return out / f0_pn

    return law


def tabulated_force(d, distance, force, skyrmion_diameter: float, force_scale: float):
    """|F|/F₀ of a tabulated law at ``d`` skyrmion diameters (see :func:`tabulated_law`)."""
    return tabulated_law(distance, force, skyrmion_diameter, force_scale)(d)


def cutoff_distance(law, fraction: float = DEFAULT_CUTOFF_FRACTION, d_max: float = 50.0) -> float:
    """Distance (skyrmion diameters) beyond which ``law(d) < fraction`` for all larger d.

    ``law`` is a vectorised callable of d. Searched on a fine grid up to ``d_max``.
    """
    if not 0 < fraction < 1:
        raise InputError("cutoff_fraction", fraction, "a fraction of F0 strictly between 0 and 1")
    d = np.linspace(0.0, d_max, 200_001)
    above = np.nonzero(law(d) >= fraction)[0]
    if len(above) == 0:
        return 0.0
    if above[-1] == len(d) - 1:
        raise InputError(
            "force law", law, f"a force that falls below {fraction} F0 within {d_max} diameters"
        )
    return float(d[above[-1] + 1])


@dataclass(frozen=True)
class ForceTable:
    """A force law sampled on a uniform grid, for linear interpolation inside kernels.

    Two layouts:
    - ``squared=False``: ``values[i]`` is |F| [pN] at distance r = i·spacing [nm] (wall law);
    - ``squared=True``: ``values[i]`` is |F|/r [pN/nm] at r² = i·spacing [nm²] (pair law): the
      kernel then needs neither a square root nor a division per pair, and F = (|F|/r)·(dx, dy).
      Node 0 (r = 0) holds the value at r² = spacing/4 to stay finite.
    Beyond ``cutoff`` [nm] the force is zero. :meth:`max_relative_error` measures the
    interpolation error against the exact law between the nodes.
    """

    values: np.ndarray
    spacing: float
    cutoff: float
    squared: bool = False

    @classmethod
    def from_law(
        cls,
        law,
        force_scale: float,
        length_unit: float,
        cutoff_fraction: float,
        n_points: int = 4096,
        squared: bool = False,
        d_max: float = 50.0,
    ) -> ForceTable:
        """Tabulate ``force_scale · law(r / length_unit)`` up to the law's cutoff (nm, pN).

        The cutoff is searched up to ``d_max`` diameters (:func:`cutoff_distance`).
        """
        cutoff = cutoff_distance(law, cutoff_fraction, d_max) * length_unit
        extent = cutoff * cutoff if squared else cutoff
        spacing = extent / (n_points - 1) if cutoff > 0 else 1.0
        nodes = np.arange(n_points + 1) * spacing  # one extra node so the cutoff interpolates
        if squared:
            r = np.sqrt(np.maximum(nodes, spacing / 4))
            values = force_scale * law(r / length_unit) / r
        else:
            values = force_scale * law(nodes / length_unit)
        values[nodes > extent] = 0.0
        return cls(np.ascontiguousarray(values), float(spacing), float(cutoff), squared)

    def __call__(self, r):
        """Interpolated |F| [pN] at distances ``r`` [nm], exactly as the kernels compute it."""
        r = np.maximum(np.asarray(r, dtype=float), 0.0)
        coord = r * r if self.squared else r
        out = np.interp(coord / self.spacing, np.arange(len(self.values)), self.values)
        if self.squared:
            out = out * r
        return np.where(r < self.cutoff, out, 0.0)

    def max_relative_error(
        self, law, force_scale: float, length_unit: float, r_min: float = 0.0
    ) -> float:
        """Largest |table − law|/law between nodes, for r_min ≤ r < cutoff (nm)."""
        mid = (np.arange(len(self.values) - 2) + 0.5) * self.spacing
        r = np.sqrt(mid) if self.squared else mid
        r = r[(r < self.cutoff) & (r >= r_min)]
        exact = force_scale * law(r / length_unit)
        return float(np.max(np.abs(self(r) - exact) / exact))


def pair_law(name: str, pair_coefficients, **params):
    """The pair law ``name`` as a one-argument callable of d (skyrmion diameters).

    ``"paper"`` uses the material's [a₂, a₁, a₀]; ``"lin-reichhardt"`` takes ``amplitude``
    and ``decay_length`` (diameters).
    """
    if name == "paper":
        a2, a1, a0 = pair_coefficients
        return lambda d: paper_pair_force(d, a2, a1, a0)
    if name == "lin-reichhardt":
        return lambda d: lin_reichhardt_pair_force(d, **params)
    raise InputError(
        "forces.pair_law",
        name,
        "'paper' or 'lin-reichhardt' ('table' is built from the material's "
        "pair_table by tabulated_law)",
    )


def wall_law(coefficients):
    """The paper's wall law as a one-argument callable of d (skyrmion diameters)."""
    coefficients = tuple(coefficients)
    return lambda d: paper_wall_force(d, coefficients)


def wall_potential(d, coefficients, d_max: float | None = None):
    """U(d)/(F₀ d_sk) = ∫_d^{d_max} |F(s)|/F₀ ds, the wall law's potential (dimensionless).

    ``d_max`` defaults to the law's cutoff; U is zero beyond it. Used for Boltzmann checks.
    """
    from scipy import integrate

    law = wall_law(coefficients)
    if d_max is None:
        d_max = cutoff_distance(law)
    d = np.atleast_1d(np.asarray(d, dtype=float))
    out = np.array([integrate.quad(law, min(x, d_max), d_max)[0] for x in d])
    return out
