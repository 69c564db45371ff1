"""``skygas infer``'s quality checks: each verdict against its stated tolerance.

The checks are built from inference.json's numbers (:func:`skygas.inference.selfcheck.
quality_checks`), so they are tested here on summaries written by hand: the model's MSD 15–35 %
below the movie's with small errors and with large ones, frames too coarse with and without a
correction, and the MSD figure's lines at the Ds they are labelled with.
"""

from __future__ import annotations

import numpy as np
import pytest

from skygas.inference import report, selfcheck

TAU = [0.01, 0.03, 0.1]
MOVIE = [4.0e-13, 3.6e-13, 3.2e-13]


def msd_check(model: list[float], movie_error: float, model_error: float) -> dict:
    """A consistency check whose MSD comparison is ``model`` against :data:`MOVIE`.

    The errors as shares of the values; g(r) not judged, the density map passed.
    """
    movie, model_ = np.array(MOVIE), np.array(model)
    e_movie, e_model = movie_error * movie, model_error * model_
    z = (model_ - movie) / np.hypot(e_movie, e_model)
    relative = model_ / movie - 1
    within_errors = bool(np.all(np.abs(z) <= selfcheck.MAX_Z))
    within = bool(np.all(np.abs(relative) <= selfcheck.MSD_TOLERANCE))
    return {
        "msd": {
            "lag_time_s": TAU,
            "movie_msd_over_4tau_m2_s": MOVIE,
            "movie_error_m2_s": e_movie.tolist(),
            "model_msd_over_4tau_m2_s": model,
            "model_error_m2_s": e_model.tolist(),
            "z": z.tolist(),
            "relative_deviation": relative.tolist(),
            "within_errors": within_errors,
            "within_tolerance": within,
            "max_z": selfcheck.MAX_Z,
            "tolerance": selfcheck.MSD_TOLERANCE,
            "passed": within_errors and within,
        },
        "pair_correlation": {"chi2_per_bin": None, "bins_compared": 0, "judged": False},
        "density": {"chi2_per_node": 1.2, "nodes_compared": 40},
    }


def by_name(checks: list[dict]) -> dict[str, dict]:
    return {c["name"]: c for c in checks}


def test_a_model_35_percent_below_the_movie_fails_both_msd_checks():
    # 15, 25 and 35 % below the movie, each value known to 2 %
    checks = by_name(
        selfcheck.comparison_checks(msd_check([3.4e-13, 2.7e-13, 2.08e-13], 0.02, 0.02))
    )
    tolerance = checks["self-check: MSD(τ)/4τ within 20 %"]
    assert not tolerance["passed"]
    assert tolerance["value"] == pytest.approx(-0.35) and tolerance["tolerance"] == 0.2
    assert "is −35 % off the movie's at τ = 100 ms" in tolerance["what"]
    errors = checks["self-check: MSD(τ)/4τ within its errors"]
    # the largest deviation in combined errors: 0.35/√(0.02² + (0.65·0.02)²) = 14.7
    assert errors["value"] == pytest.approx(-0.35 / np.hypot(0.02, 0.65 * 0.02))
    assert not errors["passed"]
    assert checks["self-check: density map"]["passed"]
    assert "self-check: g(r)" not in checks  # not judged without a pair law: not a check
    lines = selfcheck.summary_lines(msd_check([3.4e-13, 2.7e-13, 2.08e-13], 0.02, 0.02))
    assert len(lines) == 2 and all(line.startswith("the model's MSD(τ)/4τ") for line in lines)


def test_within_errors_as_large_as_a_short_movies_is_not_within_the_tolerance():
    # 35 % below, but each value uncertain by 30 %: the movie cannot tell, and the report says
    # the model is 35 % off all the same
    check = msd_check([3.4e-13, 2.7e-13, 2.08e-13], 0.3, 0.3)
    checks = by_name(selfcheck.comparison_checks(check))
    assert checks["self-check: MSD(τ)/4τ within its errors"]["passed"]
    assert not checks["self-check: MSD(τ)/4τ within 20 %"]["passed"]
    assert not check["msd"]["passed"]


def test_ten_percent_off_with_tiny_errors_fails_only_the_errors():
    checks = by_name(
        selfcheck.comparison_checks(msd_check([4.4e-13, 3.96e-13, 3.52e-13], 1e-3, 1e-3))
    )
    assert not checks["self-check: MSD(τ)/4τ within its errors"]["passed"]
    assert checks["self-check: MSD(τ)/4τ within 20 %"]["passed"]
    assert checks["self-check: MSD(τ)/4τ within 20 %"]["value"] == pytest.approx(0.1)


def summary(share=0.0, made=False, converged=None, applied=False, fixed=True, check=None):
    return {
        "sampling_correction": {
            "drift_share_of_raw_d": share,
            "threshold": 0.05,
            "made": made,
            "converged": converged,
            "applied": applied,
            "rounds": [{}, {}] if made else [],
        },
        "diffusion_constant_fixed_by_data": fixed,
        "diffusion_constant_note": None if fixed else "the frames are too coarse for the forces",
        "consistency_check": check,
    }


@pytest.mark.parametrize(
    ("case", "passed"),
    [
        (summary(share=0.01), True),  # fine frames
        (summary(share=0.3, made=True, converged=True, applied=True), True),  # corrected
        (summary(share=0.3, made=True, converged=False, fixed=False), False),  # did not converge
        (summary(share=0.3), False),  # coarse, and no correction made (--check-frames 0)
    ],
)
def test_the_frames_check_passes_only_fine_or_corrected_frames(case, passed):
    (check,) = selfcheck.quality_checks(case)
    assert check["passed"] is passed
    assert check["value"] == case["sampling_correction"]["drift_share_of_raw_d"]
    assert check["tolerance"] == 0.05
    if not passed and not case["sampling_correction"]["made"]:
        assert "no correction was made" in check["what"]


def test_the_msd_figure_draws_each_d_at_its_own_value(monkeypatch):
    """The reported case: the fit's own D 4.50e-9, the corrected D 4.18e-9, both drawn."""
    drawn = []
    monkeypatch.setattr(report, "_png", lambda fig: drawn.append(fig) or b"")
    s = summary(share=0.3, made=True, converged=True, applied=True)
    s["consistency_check"] = msd_check([3.4e-13, 2.7e-13, 2.08e-13], 0.3, 0.3)
    s |= {
        "diffusion_constant": 4.18e-9,
        "diffusion_constant_as_read": 4.41e-9,
        "diffusion_constant_msd_fit": 4.50e-9,
    }
    _, caption = report.msd_figure(s)
    (fig,) = drawn
    lines = {line.get_label(): line.get_ydata()[0] for line in fig.axes[0].get_lines()}
    assert lines[report.MSD_FIT_LINE] == 4.50e-9
    assert lines[report.MSD_CORRECTED_LINE] == 4.18e-9
    assert lines[report.MSD_AS_READ_LINE] == 4.41e-9
    assert report.MSD_MODEL_LINE not in lines
    assert "dashed, the slope D of the quadratic fit" in caption
    assert "dotted, D as the steps read it before that correction" in caption
    assert "FAILED (MSD(τ)/4τ within 20 %): the model's MSD(τ)/4τ is −35 % off" in caption
    assert "Passed (MSD(τ)/4τ within its errors)" in caption
    # the headline leads with the same verdicts
    rows = report.check_rows(s)
    assert [label for label, _ in rows[:4]] == [
        "frames resolve the motion (D, Hall angle, forces)",
        "self-check: MSD(τ)/4τ within its errors",
        "self-check: MSD(τ)/4τ within 20 %",
        "self-check: density map",
    ]
    assert rows[2][1].startswith("FAILED: ") and rows[1][1].startswith("passed: ")
    assert rows[4] == (
        "self-check: g(r)",
        "shown, not judged: the model has no pair law (g(r) then carries only the landscape, "
        "which the density map tests)",
    )
