"""What a reservoir study's report states first: the accuracies, the energy, the tables.

The reservoir's part of the report (:mod:`skygas.outputs.report`, through the device registry
:mod:`skygas.devices.registry`); the tables are in :mod:`skygas.reservoir.report`.
"""

from __future__ import annotations

from skygas.core.headline import Results, none
from skygas.core.quantities import format_value


def reservoir(s: dict) -> Results:
    """XOR, the mean of the 16 functions, the temporal tasks (68 % intervals), the energy.

    With the tables of :mod:`skygas.reservoir.report`.
    """
    from skygas.reservoir.report import accuracy_text, boolean_table, describe, temporal_table

    r = Results()
    xor = s.get("xor") or {}
    text = accuracy_text(xor) if xor.get("accuracy") is not None else None
    if text is not None:
        chance = format_value(xor["chance"], kind="percent")
        text += f" on {xor['n_test']} test inputs (chance {chance})"
    r.rows.append(("XOR test accuracy", text or none("no test input")))
    r.add("mean_accuracy", s.get("mean_accuracy"), reason="no test input")
    temporal = s.get("temporal") or {}
    for k, t in (temporal.get("recall") or {}).items():
        r.rows.append(
            (
                f"recall of input a, {k} input(s) back",
                accuracy_text(t) if t.get("accuracy") is not None else none("no test input"),
            )
        )
    if temporal.get("parity_last_two"):
        t = temporal["parity_last_two"]
        r.rows.append(
            (
                "parity of the last two inputs",
                accuracy_text(t) if t.get("accuracy") is not None else none("no test input"),
            )
        )
    r.add("energy_per_operation_J", s.get("energy_per_operation_J"), reason="no drive")
    r.keys |= {"xor", "accuracy", "temporal", "boolean"}
    if "device" in s and "boolean" in s:
        r.notes += describe(s)
        r.tables.append(("Boolean functions (test accuracy, 68 % interval)", boolean_table(s)))
        if temporal:
            r.tables.append(("Temporal tasks", temporal_table(s)))
    return r
