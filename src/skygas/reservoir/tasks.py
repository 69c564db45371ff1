"""The reservoir's tasks: all 16 Boolean functions of two inputs, and temporal tasks.

Boolean: each held input (a, b) has a reservoir state (its feature vector); a separate linear
read-out is trained for each of the 16 functions f(a, b) on the same states. A function is
numbered by its truth table, bit 2a + b of the number being f(a, b) (AND = 8, XOR = 6, ...).

Temporal (inputs a_n of the stream, one held input after another): *recall* of a_{n−k} for each
delay k, which measures the fading memory (accuracy falls to chance as k grows), and the
*parity* a_n ⊕ a_{n−1} of the last two inputs, which needs memory and a non-linearity.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from skygas.reservoir.readout import fit_and_score, split

#: The 16 Boolean functions of (a, b), by truth-table number.
BOOLEAN_NAMES = {
    0: "FALSE",
    1: "NOR",
    2: "NOT A AND B",
    3: "NOT A",
    4: "A AND NOT B",
    5: "NOT B",
    6: "XOR",
    7: "NAND",
    8: "AND",
    9: "XNOR",
    10: "B",
    11: "NOT A OR B",
    12: "A",
    13: "A OR NOT B",
    14: "OR",
    15: "TRUE",
}
#: Order in which they are reported: XOR first.
BOOLEAN_ORDER = [6] + [k for k in range(16) if k != 6]


def boolean_value(number: int, a, b) -> np.ndarray:
    """f(a, b) of the function with truth-table ``number`` (arrays of 0/1)."""
    return (number >> (2 * np.asarray(a, int) + np.asarray(b, int))) & 1


def boolean_study(
    features: np.ndarray, bits: np.ndarray, train, test, **readout
) -> dict[str, dict]:
    """Scores of the 16 functions (XOR first) on the states ``features`` of ``bits`` (n, 2)."""
    return {
        BOOLEAN_NAMES[k]: {
            "truth_table": k,
            **fit_and_score(
                features, boolean_value(k, bits[:, 0], bits[:, 1]), train, test, **readout
            ),
        }
        for k in BOOLEAN_ORDER
    }


def temporal_study(streams, delays, test_fraction: float, seed: int, **readout) -> dict:
    """Recall of input a k steps back (each k in ``delays``) and parity a_n ⊕ a_{n−1}.

    From the state at step n; states whose history starts before the stream are left out.
    """
    deepest = max([1, *delays])
    feats = np.concatenate([s.features[deepest:] for s in streams])
    a = [s.bits[:, 0] for s in streams]
    train, test = split(len(feats), test_fraction, seed + 1)
    out: dict[str, Any] = {"recall": {}}
    for k in delays:
        label = np.concatenate([x[deepest - k : len(x) - k] for x in a])
        out["recall"][str(k)] = fit_and_score(feats, label, train, test, **readout)
    parity = np.concatenate([x[deepest:] ^ x[deepest - 1 : -1] for x in a])
    out["parity_last_two"] = fit_and_score(feats, parity, train, test, **readout)
    return out
