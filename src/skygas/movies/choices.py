"""The tracker's settings chosen from the movie itself, each one recorded with how it was found.

From a few frames spread over the movie (``SAMPLE_FRAMES``):

- **contrast sign**: the skewness of the high-passed pixel values (the frame minus its
  Gaussian-blurred self, σ = ``BACKGROUND_SIGMA_PX`` or 1/16 of the frame): sparse dark cores
  on a film give a negative skew, bright ones a positive one. ``|skew| < MIN_SKEW`` is too
  weak to tell, and ``--contrast`` must say;
- **noise level** σ_n: from the second differences of neighbouring pixels, their central 80 %
  (:func:`noise_sigma`; the blur of the spots still adds a little: 2.41 counts measured on the
  shipped movie, whose noise is 2.3);
- **feature size**: the mean autocorrelation A(r) of the high-passed frames, fitted over
  r = 1 … 10 px by a·exp(−r²/4σ²) + b (a Gaussian spot of standard deviation σ has an
  autocorrelation of standard deviation σ√2; lag 0, which holds the white noise, is left out).
  trackpy's ``diameter`` is the odd integer 2⌈2σ⌉ + 1 (at least 5) and its ``separation``
  ⌈2σ⌉ + 1: neighbours closer than that merge;
- **mass threshold** (trackpy's ``minmass``): the same detector run on frames of pure white
  noise of σ_n, of the movie's size: twice the largest mass found there. A real spot's mass
  over this threshold is the ``mass_margin`` recorded;
- **search range**: features of consecutive frames matched to their nearest neighbour; the
  90th percentile r₉₀ of these steps gives the per-axis step σ_s = r₉₀/√(2 ln 10) of a 2-D
  Gaussian step, and the search range is 6 σ_s (a step beyond it has probability
  exp(−18) ≈ 1.5×10⁻⁸), at least 1 px and at most half the median distance between
  neighbours in a frame;
- **memory** (frames a skyrmion may be missed and still keep its track): 3 unless given.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from skygas.core.errors import InputError

#: frames looked at to choose the settings (spread over the movie)
SAMPLE_FRAMES = 10
#: the high-pass that removes the background before the statistics [px]
BACKGROUND_SIGMA_PX = 8.0
#: the weakest skewness that tells dark from bright
MIN_SKEW = 0.1
#: the largest autocorrelation lag fitted [px]
MAX_LAG = 10
#: frames a skyrmion may be missed and still keep its track
DEFAULT_MEMORY = 3
#: trackpy clips the band-passed frame below this fraction of the noise level σ_n (its own
#: default, 1/255 for a float frame, would depend on the frame's units: a Kerr difference image
#: of amplitude 10⁻⁴ would be clipped away)
CLIP_FRACTION = 1e-3
#: the variance of a standard normal law cut to its central 80 %: 1 − 2 z φ(z)/0.8, z = 1.2816
TRIMMED_VARIANCE = 0.437725
#: the smallest side [px] of a frame whose feature size is found from the data: the
#: autocorrelation is fitted at lags 1 … ``MAX_LAG`` px from the centre
AUTO_MIN_SIDE = 2 * MAX_LAG + 1


def required_side(diameter: int | None) -> int:
    """The smallest frame side [px] that holds a skyrmion of ``diameter`` px with film around it.

    trackpy drops the features within ``diameter // 2`` of an edge, and its band pass needs
    the film around a spot: 2 × diameter + 1 px. Without a diameter, :data:`AUTO_MIN_SIDE`.
    """
    return AUTO_MIN_SIDE if diameter is None else 2 * int(diameter) + 1


@dataclass
class Choices:
    """The tracker's settings (pixels and frames) and the statistics they came from.

    ``sources`` names, per setting, ``"given"`` or ``"from the data"``;
    ``most_per_sample_frame`` is the most skyrmions found in one of the sample frames.
    """

    contrast: str
    skewness: float
    noise_sigma: float
    feature_sigma_px: float
    diameter: int
    separation: int
    minmass: float
    mass_margin: float
    search_range: float
    step_sigma_px: float
    neighbour_distance_px: float
    memory: int
    most_per_sample_frame: int = 0
    sources: dict[str, str] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        """The choices as a JSON-able dict."""
        return asdict(self)

    def locate_options(self) -> dict:
        """The keyword arguments of ``trackpy.locate``."""
        return {
            "diameter": self.diameter,
            "minmass": self.minmass,
            "separation": self.separation,
            "threshold": CLIP_FRACTION * self.noise_sigma,
        }


def sample_indices(n_frames: int, count: int = SAMPLE_FRAMES) -> np.ndarray:
    """Up to ``count`` frame indices spread evenly over the movie, each with a successor."""
    return np.unique(np.linspace(0, n_frames - 2, min(count, n_frames - 1)).round().astype(int))


def high_pass(image: np.ndarray) -> np.ndarray:
    """``image`` minus its Gaussian blur (σ = max(8 px, 1/16 of the smaller side))."""
    from scipy.ndimage import gaussian_filter

    sigma = max(BACKGROUND_SIGMA_PX, min(image.shape) / 16)
    return image - gaussian_filter(image, sigma, mode="reflect")


def skewness(values: np.ndarray) -> float:
    """The sample skewness E[(v − μ)³]/σ³ (0 for constant values)."""
    v = values - values.mean()
    s = v.std()
    return float(np.mean(v**3) / s**3) if s > 0 else 0.0


def noise_sigma(image: np.ndarray) -> float:
    """The white-noise level σ_n of ``image`` [counts], from its second differences.

    For white noise the second difference I[k−1] − 2I[k] + I[k+1] (along rows and columns)
    has variance 6σ_n², while a smooth picture contributes little; the spots' edges are
    left out by keeping the central 80 % of the values (10th to 90th percentile), whose
    variance is ``TRIMMED_VARIANCE`` of the whole for a normal law. Continuous in the data,
    unlike a median of integer-valued differences.
    """
    d = np.concatenate(
        [
            (image[:, 2:] - 2 * image[:, 1:-1] + image[:, :-2]).ravel(),
            (image[2:] - 2 * image[1:-1] + image[:-2]).ravel(),
        ]
    )
    d = np.sort(d)
    central = d[int(0.1 * len(d)) : int(np.ceil(0.9 * len(d)))]  # by rank: ties cut alike
    return float(np.sqrt(np.var(central) / TRIMMED_VARIANCE / 6))


def feature_sigma(images: list[np.ndarray]) -> float:
    """The spots' standard deviation σ [px] from the mean autocorrelation of ``images``.

    ``images`` are high-passed with the spots positive.
    """
    from scipy.optimize import curve_fit

    shape = images[0].shape
    power = np.zeros(shape)
    for image in images:
        power += np.abs(np.fft.fft2(image - image.mean())) ** 2
    auto = np.fft.fftshift(np.fft.ifft2(power).real)
    cy, cx = shape[0] // 2, shape[1] // 2
    yy, xx = np.indices(shape)
    r = np.hypot(yy - cy, xx - cx)
    lag = np.rint(r).astype(int)
    keep = (lag >= 1) & (lag <= MAX_LAG)
    counts = np.bincount(lag[keep], minlength=MAX_LAG + 1)[1:]
    sums = np.bincount(lag[keep], weights=auto[keep], minlength=MAX_LAG + 1)[1:]
    if not (np.all(counts > 0) and sums[0] > 0):  # frames too small, or flat at 1 px
        raise _no_feature_size()
    profile = sums / counts
    profile = profile / profile[0]
    lags = np.arange(1, MAX_LAG + 1, dtype=float)

    def model(r, a, s, b):
        return a * np.exp(-(r**2) / (4 * s**2)) + b

    try:
        (a, s, _), _ = curve_fit(model, lags, profile, p0=(1.5, 2.0, 0.0), maxfev=5000)
    except RuntimeError:
        s, a = float("nan"), 0.0
    if not (np.isfinite(s) and a > 0 and 0.3 < abs(s) < min(shape) / 4):
        raise _no_feature_size()
    return float(abs(s))


def _no_feature_size() -> InputError:
    return InputError(
        "MOVIE",
        "(feature size)",
        "spots whose size the autocorrelation of the frames shows "
        "(none was found: are there skyrmions in the movie?)",
        "give --diameter in pixels (odd, a little larger than a skyrmion's image)",
    )


def spots_bright(image: np.ndarray, contrast: str) -> np.ndarray:
    """The frame as trackpy wants it: skyrmions bright, the film at 0 (its median subtracted).

    trackpy's detector depends on the frame's offset (not on its scale): with the film at 0,
    its statistics are those of the zero-mean noise frames the threshold is taken from.
    """
    sign = -1.0 if contrast == "dark" else 1.0
    return sign * (image - np.median(image))


def _locate(image: np.ndarray, diameter: int, separation: int, minmass: float, noise: float):
    from skygas.movies.tracking import locate_frame

    return locate_frame(
        image,
        diameter=diameter,
        minmass=minmass,
        separation=separation,
        threshold=CLIP_FRACTION * noise,
    )


def _noise_minmass(
    shape: tuple[int, int], sigma: float, diameter: int, separation: int, seed: int
) -> float:
    """Twice the largest mass trackpy finds in white noise of ``sigma`` (a few frames)."""
    rng = np.random.default_rng(seed)
    largest = 0.0
    for _ in range(4):
        found = _locate(rng.normal(0.0, sigma, shape), diameter, separation, 0.0, sigma)
        if len(found):
            largest = max(largest, float(found["mass"].max()))
    return 2.0 * largest


def choose(
    movie,
    *,
    contrast: str = "auto",
    diameter: int | None = None,
    minmass: float | None = None,
    search_range: float | None = None,
    memory: int | None = None,
    seed: int = 0,
) -> Choices:
    """The tracker's settings for ``movie`` (see the module docstring); given ones are kept.

    Parameters
    ----------
    movie : Movie
        The opened movie (:func:`skygas.movies.reading.open_movie`).
    contrast : {"auto", "dark", "bright"}
        The skyrmions' contrast against the film.
    diameter : int, optional
        trackpy's feature diameter [px], odd.
    minmass : float, optional
        trackpy's mass threshold (in the movie's counts, spots made positive).
    search_range : float, optional
        The farthest a skyrmion moves between frames [px].
    memory : int, optional
        Frames a skyrmion may be missed (default 3).
    seed : int
        Seed of the noise frames of the threshold.

    Returns
    -------
    Choices
        The settings and the statistics behind them.
    """
    sources = {}
    frames = sample_indices(movie.n_frames)
    images = [movie.frame(int(i)) for i in frames]
    passed = [high_pass(im) for im in images]
    skew = skewness(np.concatenate([p.ravel() for p in passed]))
    if contrast == "auto":
        if abs(skew) < MIN_SKEW:
            raise InputError(
                "--contrast",
                "auto",
                f"a movie whose skyrmions are clearly dark or bright (the skewness of its "
                f"high-passed pixels is {skew:+.3f}, too close to 0 to tell)",
                "give --contrast dark or --contrast bright",
            )
        contrast = "dark" if skew < 0 else "bright"
        sources["contrast"] = "from the data"
    else:
        sources["contrast"] = "given"
    sign = -1.0 if contrast == "dark" else 1.0
    sigma_n = float(np.median([noise_sigma(im) for im in images]))
    spots = [sign * p for p in passed]
    size = feature_sigma(spots) if diameter is None else float("nan")
    if diameter is None:
        diameter = max(5, 2 * math.ceil(2 * size) + 1)
        sources["diameter"] = "from the data"
    else:
        sources["diameter"] = "given"
        size = (diameter - 1) / 4
    separation = max(3, math.ceil(2 * size) + 1)
    warnings = []
    signed = [spots_bright(im, contrast) for im in images]
    if minmass is None:
        minmass = _noise_minmass(images[0].shape, max(sigma_n, 1e-12), diameter, separation, seed)
        sources["minmass"] = "from the data"
    else:
        sources["minmass"] = "given"
    found = [_locate(im, diameter, separation, minmass, sigma_n) for im in signed]
    masses = np.concatenate([f["mass"].to_numpy() for f in found])
    if not len(masses):
        raise InputError(
            "MOVIE",
            str(movie.path),
            f"skyrmions brighter than the noise ({contrast} spots of diameter {diameter} px "
            f"and mass > {minmass:.4g}: none found in {len(frames)} frames)",
            "check --contrast, or give --diameter and --minmass",
        )
    margin = float(np.median(masses) / minmass) if minmass > 0 else float("inf")
    if margin < 2:
        warnings.append(
            f"the median skyrmion's mass is only {margin:.2f}× the threshold: some may be missed"
        )
    # steps between consecutive frames and distances within a frame
    from scipy.spatial import cKDTree

    steps, neighbours = [], []
    for i, f in zip(frames, found, strict=True):
        if len(f) < 1:
            continue
        xy = f[["x", "y"]].to_numpy()
        if len(xy) > 1:
            neighbours.append(cKDTree(xy).query(xy, k=2)[0][:, 1])
        nxt = spots_bright(movie.frame(int(i) + 1), contrast)
        nxt = _locate(nxt, diameter, separation, minmass, sigma_n)
        if len(nxt):
            steps.append(cKDTree(nxt[["x", "y"]].to_numpy()).query(xy)[0])
    all_steps = np.concatenate(steps) if steps else np.zeros(0)
    nn = float(np.median(np.concatenate(neighbours))) if neighbours else float("inf")
    step_sigma = (
        float(np.percentile(all_steps, 90) / math.sqrt(2 * math.log(10)))
        if len(all_steps)
        else float("nan")
    )
    if search_range is None:
        wanted = 6 * step_sigma if np.isfinite(step_sigma) else diameter
        search_range = float(min(max(wanted, 1.0), 0.5 * nn))
        if wanted > 0.5 * nn:
            warnings.append(
                f"skyrmions move about {step_sigma:.2g} px per frame, comparable with their "
                f"spacing ({nn:.3g} px): the linking may swap neighbours; record faster"
            )
        sources["search_range"] = "from the data"
    else:
        sources["search_range"] = "given"
    if memory is None:
        memory = DEFAULT_MEMORY
        sources["memory"] = "default"
    else:
        sources["memory"] = "given"
    return Choices(
        contrast=contrast,
        skewness=skew,
        noise_sigma=sigma_n,
        feature_sigma_px=size,
        diameter=int(diameter),
        separation=int(separation),
        minmass=float(minmass),
        mass_margin=margin,
        search_range=float(search_range),
        step_sigma_px=step_sigma,
        neighbour_distance_px=nn,
        memory=int(memory),
        most_per_sample_frame=max(len(f) for f in found),
        sources=sources,
        warnings=warnings,
    )
