"""Internal unit system and the conversions at the edge.

skygas computes in **nanometre, nanosecond, piconewton** (and kelvin). In these units
velocities come out in nm/ns = m/s, k_B T at 300 K is 4.14 pN·nm, and the typical skyrmion
force scale (~1 pN) and size (~40 nm) are of order one. Conversions happen once, when a
configuration is loaded or a result is written; compiled kernels never see SI values.

Derived internal units:
- energy: pN·nm = 1e-21 J
- friction (k, G, α𝒟k): pN·ns/nm = 1e-12 kg/s
- diffusion constant: nm²/ns = 1e-9 m²/s
"""

from __future__ import annotations

#: metres → nanometres
M_TO_NM = 1e9
#: seconds → nanoseconds
S_TO_NS = 1e9
#: newtons → piconewtons
N_TO_PN = 1e12
#: joules → pN·nm
J_TO_PN_NM = 1e21
#: kg/s (= N·s/m) → pN·ns/nm
KG_PER_S_TO_INTERNAL = N_TO_PN * S_TO_NS / M_TO_NM
#: m²/s → nm²/ns
M2_PER_S_TO_NM2_PER_NS = M_TO_NM**2 / S_TO_NS

#: Boltzmann constant [J/K]
BOLTZMANN = 1.380649e-23
#: Gyromagnetic ratio of the electron, magnitude [rad/(s·T)] (docs/physics.md §1)
GYROMAGNETIC_RATIO = 1.7595e11
#: Vacuum permeability [T·m/A]
MU_0 = 1.25663706212e-6
#: Bohr magneton [J/T]
BOHR_MAGNETON = 9.2740100783e-24
#: Elementary charge [C]
ELEMENTARY_CHARGE = 1.602176634e-19


def thermal_energy_internal(temperature_kelvin: float) -> float:
    """k_B T in pN·nm."""
    return BOLTZMANN * temperature_kelvin * J_TO_PN_NM
