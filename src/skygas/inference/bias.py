"""D in a crowded gas: the model's D retuned until its runs read what the movie reads.

The short-lag MSD fit (:mod:`skygas.inference.diffusion`) is exact for a free skyrmion. In a gas,
a neighbour's or a wall's push lasts a fraction of a frame, and with the gyrotropic part of the
mobility a colliding pair turns about itself: the fit reads more than the free D. In a walled
1.2 µm square of S2 on a 1.5 k_BT landscape with 5 ns frames it reads 2 % above the free D for 5
skyrmions, 7 % for 15, 15 % for 30 and 52 % for 60; without the landscape, 9 % for 30
(docs/inference.md). That excess belongs to the crowding and to the frame interval, not to the
film's mobility, so it is measured where the answer is known. Each run of the pair iterations
(:mod:`skygas.inference.pair`) is a skygas run of the inferred model's gas (its D, Hall angle,
pair law, walls and crowding-corrected pinning map; the movie's number of skyrmions, outline and
frame interval). Seen with the movie's localisation error and read by the same fit, run n gives
the ratio r_n = D̂(run n)/D_n of what the fit reads to the D the run had, and the next run gets

    D_{n+1} = D̂_movie / r_n.

The excess grows with D itself (a faster skyrmion meets more neighbours within a frame, and the
excess of a drift over a frame scales as μ²F²τ/D ∝ D), so a single such step overshoots (the
model run at the movie's D̂ reads 1.25–1.29 where the film reads 1.15 for 30 skyrmions). The
result is the D whose runs would read the movie's D̂ (indirect inference), from the excess per
unit of D that the runs show (:meth:`DiffusionTuner.result`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from skygas.analysis.frames import Frames
from skygas.inference.diffusion import estimate_diffusion
from skygas.inference.pair import seen_as_movie

#: The systematic error of the retuned D, as a share of its correction |D̂ − D|: on the round-trip
#: gases of 15 and 30 skyrmions (1000–16 000 frames) what remained after the retuning was 7–49 %
#: of the correction, 31 % in the median (docs/inference.md).
SYSTEMATIC_SHARE = 0.3


def read_run(run: Frames, sigma: float, seed: int) -> tuple[float, float]:
    """D [m²/s] ± error that the MSD fit reads off ``run`` seen with localisation error σ [m]."""
    d = estimate_diffusion(seen_as_movie(run, sigma, np.random.default_rng([seed, 0xB1A5])))
    return d.diffusion_constant, d.error


@dataclass
class DiffusionTuner:
    """Retunes the model's D after each run: D_{n+1} = D̂_movie · D_n / D̂(run n).

    ``measured`` ± ``error`` [m²/s] the movie's MSD fit; ``sigma`` [m] its localisation error;
    ``fields(D)`` the material fields of a model with that D.
    """

    measured: float
    error: float
    sigma: float
    fields: Callable[[float], dict]
    seed: int
    used: list = field(default_factory=list)
    reads: list = field(default_factory=list)
    read_errors: list = field(default_factory=list)

    @property
    def current(self) -> float:
        """The D [m²/s] of the next run."""
        if not self.reads:
            return self.measured
        return self.measured * self.used[-1] / self.reads[-1]

    def retune(self, run: Frames) -> dict:
        """Read ``run`` (made with :attr:`current`) and return the next run's material fields."""
        d_run = self.current
        read, read_error = read_run(run, self.sigma, self.seed + len(self.reads))
        self.used.append(d_run)
        self.reads.append(read)
        self.read_errors.append(read_error)
        return self.fields(self.current)

    def result(self) -> tuple[float, float]:
        """D [m²/s] ± error: the D whose runs read what the movie reads.

        Each run n gives the excess per unit of D, c_n = (r_n − 1)/D_n (the excess grows in
        proportion to D); with c their mean over the runs (the first left out when there are
        three or more: its pair law is still the raw −ln g), D solves D̂ = D (1 + c D). The
        error adds the movie's and that of c, the scatter of the c_n over √n (a run's own blocked
        error when there is one run): runs from different starting configurations read excesses
        that differ by more than their blocked errors, as the movie's configuration does.
        """
        if not self.reads:
            return self.measured, self.error
        used, reads = np.array(self.used), np.array(self.reads)
        errors = np.array(self.read_errors)
        keep = slice(1, None) if len(reads) >= 3 else slice(None)
        c_runs = (reads[keep] / used[keep] - 1.0) / used[keep]
        c = float(np.mean(c_runs))
        if len(c_runs) > 1:
            c_error = float(np.std(c_runs, ddof=1) / np.sqrt(len(c_runs)))
        else:
            c_error = float(errors[keep][0] / used[keep][0] / used[keep][0])

        def solve(c_value: float) -> float:
            if abs(c_value) * self.measured < 1e-9:
                return self.measured
            return (np.sqrt(1.0 + 4.0 * c_value * self.measured) - 1.0) / (2.0 * c_value)

        value = float(solve(c))
        spread = 0.5 * abs(solve(c + c_error) - solve(c - c_error))
        return value, float(np.hypot(value * self.error / self.measured, spread))

    def as_dict(self) -> dict:
        """JSON-able, SI units in the keys."""
        return {
            "run_diffusion_constants": self.used,
            "diffusion_constant_read_on_runs": self.reads,
            "diffusion_constant_read_on_runs_error": self.read_errors,
            "method": "each pair-iteration run of the inferred model's gas, seen with the "
            "movie's localisation error, is read by the same MSD fit; the next run's D is the "
            "movie's reading times D_run / D_read; the result solves D_movie_read = D (1 + c D) "
            "with c the runs' mean excess per unit of D",
        }
