"""The trained linear read-out.

Features → label, trained on one part of the inputs and scored on the held-out rest.

The features are standardised (zero mean, unit variance on the training set) and fed to a
ridge classifier (least squares on ±1 targets with an L2 penalty α, scikit-learn's
``RidgeClassifier``) or a logistic regression (``LogisticRegression`` with C = 1/α). The split
into training and test inputs is drawn from the seed and shared by every task of a study.

A task whose training labels are all equal (the constant Boolean functions) needs no read-out:
it predicts that label.

Scores: accuracy on the test inputs; chance = the test fraction of the majority class (what a
constant guess gets); the standard error of an accuracy at chance, √(chance·(1 − chance)/n_test);
and the margin (accuracy − chance)/standard error. The uncertainty of an accuracy itself is its
Wilson score interval (:func:`accuracy_interval`).
"""

from __future__ import annotations

import math

import numpy as np


def split(n: int, test_fraction: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Training and test indices of ``n`` inputs (a random permutation drawn from ``seed``)."""
    order = np.random.default_rng(np.random.SeedSequence([seed, 0x7E57])).permutation(n)
    n_test = max(1, min(n - 1, int(round(test_fraction * n))))
    return np.sort(order[n_test:]), np.sort(order[:n_test])


def _classifier(model: str, regularization: float):
    from sklearn.linear_model import LogisticRegression, RidgeClassifier
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    if model == "logistic":
        head = LogisticRegression(C=1.0 / regularization, max_iter=2000)
    else:
        head = RidgeClassifier(alpha=regularization)
    return make_pipeline(StandardScaler(), head)


def fit_and_score(
    features: np.ndarray,
    labels: np.ndarray,
    train: np.ndarray,
    test: np.ndarray,
    model: str = "ridge",
    regularization: float = 1e-3,
) -> dict:
    """Train on ``train``, score on ``test`` (index arrays); returns the scores (see module)."""
    x = np.asarray(features, float)
    y = np.asarray(labels).astype(int)
    if np.unique(y[train]).size < 2:
        predicted = np.full(test.size, y[train][0])
    else:
        predicted = _classifier(model, regularization).fit(x[train], y[train]).predict(x[test])
    accuracy = float(np.mean(predicted == y[test]))
    p = float(np.mean(y[test]))
    chance = max(p, 1.0 - p)
    se = math.sqrt(chance * (1.0 - chance) / test.size)
    return {
        "accuracy": accuracy,
        "chance": chance,
        "n_train": int(train.size),
        "n_test": int(test.size),
        "chance_standard_error": se,
        "margin_standard_errors": (accuracy - chance) / se if se > 0 else None,
    }


def accuracy_interval(accuracy, n_test, z: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The Wilson score interval of accuracies measured on ``n_test`` test inputs.

    With a = accuracy, n = n_test and z standard deviations (z = 1: 68 %),

        centre = (a + z²/2n) / (1 + z²/n),
        half width = z/(1 + z²/n) · √(a(1 − a)/n + z²/4n²),

    which, unlike a ± √(a(1 − a)/n), keeps a width at a = 0 or 1 and stays inside [0, 1].

    Parameters
    ----------
    accuracy : array_like
        Fractions of the test inputs classified right.
    n_test : array_like
        Test inputs of each accuracy.
    z : float
        Width in standard deviations.

    Returns
    -------
    tuple of numpy.ndarray
        The interval's lower and upper ends.
    """
    a = np.asarray(accuracy, float)
    n = np.asarray(n_test, float)
    shrink = 1.0 + z**2 / n
    centre = (a + z**2 / (2 * n)) / shrink
    half = z / shrink * np.sqrt(a * (1 - a) / n + z**2 / (4 * n**2))
    return centre - half, centre + half
