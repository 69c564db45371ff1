"""The calibrated annihilation model and the fit behind the quick saturation estimate.

Fitted to ONE observation of the paper (docs/physics.md §4): a 1024 nm chamber holds about 90
skyrmions of ≈ 39 nm at 300 K (maximum-density figure), with the saturation protocol of
:mod:`skygas.neuron.saturation`. Γ0 = 1e6 /s (the isolated skyrmion's leak, 1 µs) and
d_min = one diameter are set, not fitted; with c = 8 the plateau survivor count (4 repetitions,
N = 250/400/600) was 92/95/94 at r_c = 2.4 d_sk and 86/88/88 at r_c = 2.5 d_sk, so
r_c = 2.45 d_sk (:data:`~skygas.neuron.annihilation.CROWDING_DIAMETERS`). The other diameters
are predictions (docs/neuron.md).
"""

from skygas.neuron.annihilation import AnnihilationModel

CALIBRATED = AnnihilationModel(base_rate=1e6, compression_sensitivity=8.0)

#: N_sat ≈ a·((D − b·r_c)/r_c)²: N/(D/r_c)² was 0.735/0.749/0.73/0.768 at 256/384/512/768 nm
#: (docs/neuron.md), so a = 0.75, b = 0. Used only to
#: refuse thresholds the chamber cannot reach and to choose the trial numbers.
SATURATION_DENSITY_FIT = {"a": 0.75, "b": 0.0}
