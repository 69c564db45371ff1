"""Figure details a reader relies on: a fitted curve says whether it meets the data."""

from __future__ import annotations

import numpy as np

from skygas.sweep.figures import fit_label


def test_fit_label_says_when_a_fit_misses_the_data():
    x = np.linspace(1, 2, 6)
    sem = np.full(6, 0.01)
    rng = np.random.default_rng(0)
    data = x**2 + rng.normal(0, 0.01, 6)
    label, style = fit_label("fit", x**2, data, sem)
    assert "misses" not in label and style == "-"
    # χ²/dof of the exact model is that of 6 unit normals over 4 dof: below 3 for this seed
    label, style = fit_label("fit", x**2 + 0.1, data, sem)  # 10 standard errors off
    assert "misses the data" in label and style == "--"
    assert "too few" in fit_label("fit", x[:2], x[:2], sem[:2])[0]
