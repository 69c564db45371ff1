r"""``device = "analytic"``: a known function of the configuration, for checking a study.

Not a skyrmion device: a trial of it costs microseconds (plus ``delay``), its optimum is known
exactly, and its noise is whatever ``noise`` says. It checks the optimiser, the study's
machinery and an installation (``docs/optimize.md``) before real runs are spent on them.

Summary quantities, with :math:`\mathbf{r} = (x, y, z)`:

- ``f`` :math:`= |\mathbf{r} - \mathbf{a}|^2 + \sigma\,\xi_1`, the squared distance to
  ``center`` :math:`\mathbf{a}`, smallest (0) at :math:`\mathbf{r} = \mathbf{a}`;
- ``h`` :math:`= |\mathbf{r} - \mathbf{b}|^2 + \sigma\,\xi_2`, the same to ``second_center``
  :math:`\mathbf{b}` (two objectives in conflict: their Pareto set is the segment
  :math:`\mathbf{a}\mathbf{b}`);
- ``x``, ``y``, ``z``: the point itself (for constraints such as ``x + y < 1``);

where :math:`\xi_{1,2}` are independent standard normal numbers drawn from ``seed`` and
:math:`\sigma` is ``noise``. ``shape = "b"`` adds 1 to ``f`` (a choice with a known best).
"""

from __future__ import annotations

import time
from typing import Literal

import numpy as np
from pydantic import Field

from skygas.core.config_types import StrictModel

#: Its name in study files.
NAME = "analytic"
#: The summary quantities of the analytic device.
QUANTITIES = ("f", "h", "x", "y", "z")
#: A study file without ``[base]``: the defaults.
DEFAULT_BASE: dict = {}
#: Fields a study of it varies.
EXAMPLE_FIELDS = "x, y, z"


class AnalyticConfig(StrictModel):
    """The point :math:`(x, y, z)`, the two centres, the noise σ, a choice and a delay [s]."""

    seed: int = Field(0, ge=0, lt=2**63)
    # |r| up to 1e100: the squared distance stays a finite number
    x: float = Field(0.0, ge=-1e100, le=1e100)
    y: float = Field(0.0, ge=-1e100, le=1e100)
    z: float = Field(0.0, ge=-1e100, le=1e100)
    center: tuple[float, float, float] = (0.3, -0.2, 0.0)
    second_center: tuple[float, float, float] = (-0.5, 0.4, 0.0)
    noise: float = Field(0.0, ge=0)
    shape: Literal["a", "b"] = "a"
    delay: float = Field(0.0, ge=0, le=60)  # s of sleep per run: a run that takes time


def evaluate(config: AnalyticConfig) -> dict[str, float]:
    """The summary of one run of the analytic device (see the module docstring)."""
    if config.delay:
        time.sleep(config.delay)
    r = np.array([config.x, config.y, config.z])
    xi = np.random.default_rng(config.seed).standard_normal(2)
    f = float(np.sum((r - np.array(config.center)) ** 2)) + config.noise * xi[0]
    h = float(np.sum((r - np.array(config.second_center)) ** 2)) + config.noise * xi[1]
    return {
        "f": f + (1.0 if config.shape == "b" else 0.0),
        "h": h,
        "x": config.x,
        "y": config.y,
        "z": config.z,
    }


# -- its study hooks (skygas.devices.study_hooks.StudyPoints) ----------------------------------
def model() -> type:
    """:class:`AnalyticConfig`."""
    return AnalyticConfig


def point(base: dict, overrides: dict, what: str) -> AnalyticConfig:
    """``base`` with the dotted ``overrides`` set, validated; an error names ``what``."""
    from pydantic import ValidationError

    from skygas.core.config_types import apply_overrides, to_input_error
    from skygas.core.errors import InputError

    try:
        try:
            return AnalyticConfig(**apply_overrides(base, overrides))
        except ValidationError as err:
            raise to_input_error(err, "") from None
    except InputError as err:
        label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
        raise InputError(f"{what} ({label}): {err.field}", err.value, err.allowed) from None


def estimate(config: AnalyticConfig):
    """A known function: its ``delay`` [s] and nothing else."""
    from skygas.core.estimates import Estimate

    return Estimate(steps=1.0, memory=0.0, seconds=float(config.delay))


def run(config_json: str) -> dict[str, float]:
    """One run, from its configuration's JSON (:func:`evaluate`)."""
    return evaluate(AnalyticConfig.model_validate_json(config_json))
