"""The micromagnetic solver: magnum.np (PyTorch), behind three calls.

This is the only module that imports torch and magnum.np. It offers, for one film
(:class:`Film`) of one material (:class:`~skygas.calibration.material.MicromagneticMaterial`):

- :meth:`FilmSolver.energy`: the micromagnetic energy of a texture, term by term;
- :meth:`FilmSolver.relax`: the nearest energy minimum (the Barzilai–Borwein minimiser of
  magnum.np's ``MinimizerBB``, Exl et al., J. Appl. Phys. 115, 17D118 (2014), preconditioned
  against the exchange field's short waves), optionally with the skyrmions' guiding centres
  held at given points (Lagrange multipliers);
- :meth:`FilmSolver.evolve`: Landau–Lifshitz–Gilbert dynamics at T = 0 (magnum.np's adaptive
  Runge–Kutta–Fehlberg 4(5)), with the material's own γ and α.

The energy includes exchange, interfacial (or bulk) DMI, uniaxial anisotropy, the Zeeman
energy of B_z and the full stray field (FFT demagnetisation, open boundaries). Textures are
NumPy arrays of shape (nx, ny, 3) (x first, as magnum.np stores them).

Threads and devices: :func:`configure` must run before the first solve. On a CPU, each process
uses ``threads`` torch threads (one, when several solves run side by side: two OpenMP threads
per process with another busy process on the machine made a relaxation 25 times slower). When
torch sees a CUDA GPU, magnum.np runs there.
"""

from __future__ import annotations

import logging
import math
import os
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from skygas.calibration.material import MicromagneticMaterial
from skygas.core.errors import InputError

#: Default convergence of a relaxation: max |m × (m × H_eff)| below this [A/m].
DEFAULT_TORQUE_TOLERANCE = 1.0

_settings: dict[str, Any] = {"threads": 1, "compile": True, "configured": False}


def configure(threads: int = 1, compile: bool = True) -> None:
    """Set torch's thread count and whether magnum.np's field terms are compiled.

    ``torch.compile``: about 25 % faster per evaluation, about 20 s to compile once per process with
    a cold cache. Call before the first solve of the process.
    """
    if _settings["configured"]:
        return  # torch is imported: its threads and compilation are set for this process
    if not compile:
        os.environ["TORCHDYNAMO_DISABLE"] = "1"
    _settings.update(threads=int(threads), compile=bool(compile))


def use_threads(threads: int) -> None:
    """Give this process's next solves ``threads`` torch threads (intra-op), once torch is set up.

    A calibration's local workers are single-threaded while relaxations share the cores; when the
    validation's LLG is all that is left it takes the idle cores too (S2: 43 against 64 ms per
    step on 2 cores). LLG's bits do not depend on the count (``tests/calibration/test_solver.py``),
    so a resumed run repeats its pieces exactly whichever count they get.
    """
    if not _settings["configured"]:  # torch is set up with them on the first solve
        _settings["threads"] = int(threads)
        return
    import torch

    if torch.get_num_threads() != int(threads):
        torch.set_num_threads(int(threads))


def require_installed() -> None:
    """Refuse, with one line, to start a calibration without torch and magnum.np.

    Checked without importing them.
    """
    from importlib.util import find_spec

    for package, install in (
        ("torch", "`pip install torch==2.13.0` (a CPU build; see the README for a GPU)"),
        ("magnumnp", "`pip install 'skygas[micromagnetics]'`"),
    ):
        if find_spec(package) is None:
            raise InputError(
                "micromagnetics",
                f"{package} not installed",
                "torch and magnum.np for `skygas calibrate`",
                f"install {install}",
            )


def gpu_available() -> bool:
    """True if torch sees a CUDA GPU (imports torch, not magnum.np)."""
    try:
        import torch
    except ImportError:
        return False
    return bool(torch.cuda.is_available())


def default_workers() -> int:
    """Solver processes: two on a CPU (or as many as there are cores if fewer), none on a GPU.

    On a CPU each has one torch thread (two threads per process with another busy process beside it
    made a relaxation 25 times slower); on a GPU one process drives it.
    """
    return 0 if gpu_available() else cpu_workers()


def cpu_workers() -> int:
    """Solver processes on a CPU: two, or as many as there are cores if fewer."""
    return max(1, min(2, os.cpu_count() or 1))


#: glibc's mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def keep_freed_memory() -> None:
    """Let this process's malloc reuse freed memory instead of handing it back to the system.

    Dask starts its worker processes with ``MALLOC_TRIM_THRESHOLD_=65536`` (so that their memory
    shrinks when work ends), and glibc then serves every allocation above 128 kB by a fresh
    mmap, page faults and all. A solver allocates field-sized temporaries (0.5–4 MB) at every
    evaluation: in a Dask worker S2's validation LLG took 0.43 s per step against 0.17 s in a
    plain process, a relaxation 52 s against 19 s. The heap's limits are set back here, for
    whatever process solves (a local worker, a running cluster's, or this one): allocations
    below 32 MB from the heap, and freed memory kept up to 256 MB. Linux with glibc only;
    elsewhere nothing changes.
    """
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("c")
    if name is None:
        return
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return
    mallopt(_M_MMAP_THRESHOLD, 32 * 2**20)
    mallopt(_M_TRIM_THRESHOLD, 256 * 2**20)


def backend():
    """magnum.np, imported on first use with its logging silenced.

    A clear error if the ``micromagnetics`` extra is not installed.
    """
    if not _settings["configured"]:
        try:
            import torch
        except ImportError:
            raise InputError(
                "micromagnetics",
                "not installed",
                "torch and magnum.np for `skygas calibrate`",
                "install them with `pip install torch==2.13.0` then "
                "`pip install 'skygas[micromagnetics]'` (see the README)",
            ) from None
        torch.set_num_threads(_settings["threads"])
        # magnum.np otherwise starts a Python subprocess at import to find a GPU
        os.environ.setdefault("CUDA_DEVICE", "0" if torch.cuda.is_available() else "-1")
        # it logs its banner at import and renames the process: keep both as they were
        # (a filter survives the level magnum.np sets on its logger)
        logging.getLogger("magnum.np").addFilter(lambda record: record.levelno >= logging.ERROR)
        title = _process_title()
        try:
            import magnumnp  # noqa: F401
        except ImportError:
            raise InputError(
                "micromagnetics",
                "not installed",
                "magnum.np for `skygas calibrate`",
                "install it with `pip install 'skygas[micromagnetics]'` (see the README)",
            ) from None
        _process_title(title)
        if not torch.cuda.is_available():
            # magnum.np makes its device the default through a torch function mode, which
            # every torch call then passes through (a third of a relaxation's time on a
            # CPU); on a CPU the default is that device anyway
            torch.set_default_device(None)
        keep_freed_memory()
        _settings["configured"] = True
    import magnumnp

    return magnumnp


def _process_title(title: str | None = None) -> str | None:
    """The process's title (what ``ps`` shows), or set it back to ``title``."""
    try:
        import setproctitle
    except ImportError:
        return None
    if title is not None:
        setproctitle.setproctitle(title)
    return setproctitle.getproctitle()


def device_name() -> str:
    """Where the solves run: ``"cpu"`` or the GPU's name."""
    import torch

    backend()
    if torch.cuda.is_available():
        return f"cuda ({torch.cuda.get_device_name(0)})"
    return "cpu"


def versions() -> dict[str, str]:
    """The solver's versions, for the model file."""
    import torch

    mn = backend()
    return {"magnumnp": mn.__version__, "torch": torch.__version__}


@dataclass(frozen=True)
class Film:
    """A rectangular mesh of nx × ny cells of ``cell_size`` [m], one cell (the film) thick.

    ``disk``: only the cells whose centres lie within the disk inscribed in the mesh are
    magnetic (the rest is empty: no magnetisation, no material). The mesh's lower-left corner
    is the origin; cell (i, j) has its centre at ((i + ½)·cell, (j + ½)·cell).

    ``compensated``: an extra out-of-plane field cancels the film's own stray-field
    deviation, H_c(r) = −M_s − H_z[ẑ](r), H_z[ẑ] the stray field of the film magnetised
    uniformly along +z. The uniform film then feels −M_s everywhere, as an infinite film does,
    so a skyrmion in it meets the film's edges only at short range: its long-range coupling to
    the edges' stray field (and the change of its size that this field causes) is gone. The
    laws are calibrated in such films; the particle model adds the edges' stray field for the
    device's own outline (:mod:`skygas.fields.landscape.stray_field`). ``reference_field`` [A/m] is
    added along +z in a compensated film: the stray field that the interior of the device the
    model is meant for has on top of an infinite film's. ``real_left_edge``: the compensation
    leaves the stray field of the film's left edge (x = 0), (M_s/π)·atan(h/x), h = t/2: the
    film is then a half-plane with one real straight edge.
    """

    nx: int
    ny: int
    cell_size: float
    disk: bool = False
    compensated: bool = False
    reference_field: float = 0.0
    real_left_edge: bool = False

    @property
    def size(self) -> tuple[float, float]:
        """(width, height) [m]."""
        return self.nx * self.cell_size, self.ny * self.cell_size

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """Cell-centre coordinates x, y [m], arrays of shape (nx, ny)."""
        x = (np.arange(self.nx) + 0.5) * self.cell_size
        y = (np.arange(self.ny) + 0.5) * self.cell_size
        return np.meshgrid(x, y, indexing="ij")

    @property
    def radius(self) -> float:
        """The disk's radius [m] (half the shorter side)."""
        return 0.5 * min(self.size)

    def magnetic(self) -> np.ndarray:
        """Which cells hold magnetisation, shape (nx, ny)."""
        if not self.disk:
            return np.ones((self.nx, self.ny), dtype=bool)
        x, y = self.centres()
        cx, cy = 0.5 * self.nx * self.cell_size, 0.5 * self.ny * self.cell_size
        return np.hypot(x - cx, y - cy) <= self.radius

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """The cell whose centre is nearest to (x, y) [m]."""
        # round, not floor: 150e-9 / 2e-9 is 74.99999999999999 in floating point
        return (
            min(max(int(round(x / self.cell_size - 0.5)), 0), self.nx - 1),
            min(max(int(round(y / self.cell_size - 0.5)), 0), self.ny - 1),
        )


#: The minimiser's smoothing length ℓ in exchange lengths √(2A/(μ₀M_s²)): S2's isolated
#: skyrmion (2 nm cells, 30 A/m) took 354, 297 and 315 iterations at 1, 2 and 4 of them.
SMOOTHING_LENGTHS = 2.0


class _Smoother:
    """P = (1 − ℓ²∇²)⁻¹ and P⁻¹ on a film's vector fields, the relaxation's preconditioner.

    ∇² is the five-point Laplacian of the film's cells, applied by FFT on a mesh zero-padded to
    a size with small prime factors; any symmetric positive operator is a valid
    preconditioner, and the padding changes only how much this one helps, not the minimum.
    Fields have magnum.np's shape (nx, ny, 1, 3) and are zero outside the magnetic cells.
    """

    def __init__(self, film: Film, length: float, magnetic):
        import scipy.fft
        import torch

        self.nx, self.ny = film.nx, film.ny
        self.shape = (
            scipy.fft.next_fast_len(film.nx, real=True),
            scipy.fft.next_fast_len(film.ny, real=True),
        )
        options = {"device": magnetic.device, "dtype": torch.float64}
        kx = 2 * math.pi * torch.fft.fftfreq(self.shape[0], **options)
        ky = 2 * math.pi * torch.fft.rfftfreq(self.shape[1], **options)
        k2 = ((2 - 2 * torch.cos(kx))[:, None] + (2 - 2 * torch.cos(ky))[None, :]) / (
            film.cell_size**2
        )
        self._sharpen = 1.0 + length**2 * k2
        self._smooth = 1.0 / self._sharpen
        self.magnetic = magnetic

    def _apply(self, v, factor):
        import torch

        planes = v[:, :, 0, :].permute(2, 0, 1)
        spectrum = torch.fft.rfft2(planes, s=self.shape) * factor
        out = torch.fft.irfft2(spectrum, s=self.shape)[:, : self.nx, : self.ny]
        return out.permute(1, 2, 0)[:, :, None, :] * self.magnetic

    def smooth(self, v):
        """P v."""
        return self._apply(v, self._smooth)

    def sharpen(self, v):
        """P⁻¹ v (of the padded mesh: the metric of the step sizes)."""
        return self._apply(v, self._sharpen)


@dataclass(frozen=True)
class Relaxed:
    """A relaxed texture and how the relaxation went.

    ``m`` (nx, ny, 3), the energy [J] by term and in total, the iterations, whether the torque fell
    below the tolerance, the largest torque left max|m × (m × H)| [A/m] and the wall time [s].
    """

    m: np.ndarray
    energies: dict[str, float]
    energy: float
    iterations: int
    converged: bool
    torque: float
    seconds: float


@dataclass(frozen=True)
class Evolved:
    """The end of an LLG piece.

    ``m``, the time [s], the solver's next step [s], accepted steps in the piece, wall time [s].
    """

    m: np.ndarray
    time: float
    next_step: float
    steps: int
    seconds: float


class FilmSolver:
    """magnum.np's state and field terms for one film of one material (build once, reuse)."""

    TERM_NAMES = ("exchange", "dmi", "anisotropy", "zeeman", "demag")

    def __init__(self, material: MicromagneticMaterial, film: Film):
        mn = backend()
        import torch

        self.material, self.film = material, film
        t = material.film_thickness
        self.mesh = mn.Mesh((film.nx, film.ny, 1), (film.cell_size, film.cell_size, t))
        self.state = mn.State(self.mesh)
        magnetic = torch.tensor(film.magnetic()[:, :, None])
        #: (nx, ny, 1, 1): broadcasts against the (nx, ny, 1, 3) magnetisation
        self._magnetic = magnetic[..., None]
        parameters = {
            "Ms": material.saturation_magnetization,
            "A": material.exchange_stiffness,
            "Ku": material.anisotropy,
            "alpha": material.damping,
            "Di": material.dmi,
            "Db": material.bulk_dmi,
        }
        for key, value in parameters.items():
            field = self.state.Constant(0.0)
            field[magnetic] = value
            self.state.material[key] = field
        self.state.material["Ku_axis"] = self.state.Constant([0.0, 0.0, 1.0])
        dmi = mn.BulkDMIField() if material.bulk_dmi > 0 else mn.InterfaceDMIField()
        field = self.state.Constant([0.0, 0.0, material.applied_field / mn.constants.mu_0])
        demag = mn.DemagField()
        self.state.m = self.state.Constant([0.0, 0.0, 1.0]) * self._magnetic
        if film.compensated:
            uniform_z = demag.h(self.state)[..., 2:3]
            field[..., 2:3] += (
                film.reference_field - material.saturation_magnetization - uniform_z
            ) * self._magnetic
            if film.real_left_edge:
                x = torch.tensor(film.centres()[0][:, :, None, None], device=field.device)
                h = 0.5 * material.film_thickness
                field[..., 2:3] += (
                    material.saturation_magnetization / math.pi * torch.atan(h / x) * self._magnetic
                )
        self.terms = {
            "exchange": mn.ExchangeField(),
            "dmi": dmi,
            "anisotropy": mn.UniaxialAnisotropyField(),
            "zeeman": mn.ExternalField(field),
            "demag": demag,
        }

    # -- conversions ----------------------------------------------------------------------------
    def _set(self, m: np.ndarray) -> None:
        import torch

        array = np.asarray(m, dtype=np.float64).reshape(self.film.nx, self.film.ny, 1, 3)
        tensor = torch.tensor(array, device=self.state.device)
        norm = torch.linalg.norm(tensor, dim=-1, keepdim=True)
        tensor = torch.where(norm > 0, tensor / torch.clamp(norm, min=1e-300), 0.0)
        self.state.m = tensor * self._magnetic.to(self.state.device)

    def _get(self) -> np.ndarray:
        return self.state.m[:, :, 0, :].detach().cpu().numpy().copy()

    def _field(self):
        return sum(term.h(self.state) for term in self.terms.values())

    # -- the three calls ----------------------------------------------------------------------
    def energy(self, m: np.ndarray) -> dict[str, float]:
        """Energy [J] of texture ``m`` by term.

        ``exchange``, ``dmi``, ``anisotropy``, ``zeeman``, ``demag``.
        """
        self._set(m)
        return {name: float(term.E(self.state)) for name, term in self.terms.items()}

    def relax(
        self,
        m0: np.ndarray,
        centres=(),
        *,
        reach: float = 0.0,
        torque_tolerance: float = DEFAULT_TORQUE_TOLERANCE,
        max_iterations: int = 200_000,
    ) -> Relaxed:
        """Minimise the energy from ``m0`` with its skyrmions' guiding centres held at ``centres``.

        ``centres`` [(x, y), m]; the minimisation runs until max|m × (m × H')| <
        ``torque_tolerance`` [A/m].

        **The constraint.** Skyrmion a's guiding centre is X_a = Σ r q w_a / Σ q w_a, q the
        topological charge density m·(∂ₓm × ∂ᵧm) (central differences) and w_a the cells
        within ``reach`` [m] of its target that are nearer to it than to any other target.
        The minimiser follows H' = H_eff + Σ λ_{a,i} ∂X_{a,i}/∂m, the Lagrange multipliers
        λ chosen at every step so that the step leaves every X_a where it is (and pulls back
        any drift). Its minimum is the lowest energy of all textures whose skyrmions have
        these guiding centres: the energy surface E(X₁, X₂, …) of the collective coordinates
        of Thiele's theory, every other degree of freedom (radius, shape, the tails' overlap)
        relaxed. The multipliers do no work at the minimum and the energy reported is the
        micromagnetic energy alone, so holding the centres adds nothing to E; −∂E/∂X_a is the
        force on skyrmion a that the Thiele equation balances. Holding a core cell instead
        lets the skyrmion slide away from it and distorts it around that cell.

        **The minimiser.** Preconditioned Barzilai–Borwein steps (Molina & Raydan, Numer.
        Algorithms 13, 45 (1996)) of the semi-implicit midpoint rule of Exl et al. (J. Appl.
        Phys. 115, 17D118 (2014); magnum.np's ``MinimizerBB``), which keeps |m| = 1:

            m ← [(4 − τ²|d|²) m + 4τ d]/(4 + τ²|d|²),   d = T P T H',

        T the projection on the plane normal to m and P = (1 − ℓ²∇²)⁻¹ (:class:`_Smoother`,
        ℓ = :data:`SMOOTHING_LENGTHS` exchange lengths). Without P (d = T H') this is
        ``MinimizerBB``'s step. The exchange field's short waves make the energy surface
        stiff, 2A/(μ₀M_s)·8/Δx² ≈ 6·10⁷ A/m for S2 on 2 nm cells against ≈ 10⁵ A/m for the
        skyrmion's breathing, and a gradient method's iterations grow with that ratio. P
        divides the short waves by ℓ²k² and leaves the long ones: S2's isolated skyrmion took
        297 iterations instead of 2596, the same energy to 7 digits. The step sizes are
        τ = ⟨s, P⁻¹s⟩/⟨s, y⟩ and ⟨s, y⟩/⟨y, Py⟩ in turn (s the change of m, y that of
        m × (m × H')); the iteration stops on the torque of H' itself, not of P H'.
        """
        backend()
        import torch

        self._set(m0)
        state = self.state
        cell = self.film.cell_size
        targets = np.asarray(centres, dtype=float).reshape(-1, 2)
        x, y = (torch.tensor(c, device=state.device) for c in self.film.centres())
        weights = []
        if len(targets):
            distance = np.stack(
                [
                    np.hypot(self.film.centres()[0] - tx, self.film.centres()[1] - ty)
                    for tx, ty in targets
                ]
            )
            nearest = np.argmin(distance, axis=0)
            for a in range(len(targets)):
                w = (nearest == a) & (distance[a] <= reach) & self.film.magnetic()
                weights.append(torch.tensor(w, device=state.device, dtype=state.m.dtype))
        goal = torch.tensor(targets, device=state.device, dtype=state.m.dtype)

        def guiding_centres(m):
            """X_a (n, 2) [m], differentiable in m (nx, ny, 1, 3)."""
            mm = m[:, :, 0, :]
            dmx = torch.zeros_like(mm)
            dmy = torch.zeros_like(mm)
            dmx[1:-1] = (mm[2:] - mm[:-2]) / (2 * cell)
            dmy[:, 1:-1] = (mm[:, 2:] - mm[:, :-2]) / (2 * cell)
            q = (mm * torch.linalg.cross(dmx, dmy)).sum(-1)
            return torch.stack(
                [
                    torch.stack(
                        [(w * q * x).sum() / (w * q).sum(), (w * q * y).sum() / (w * q).sum()]
                    )
                    for w in weights
                ]
            )

        def constraint_gradients(m):
            """X_a and the fields ∂X_{a,i}/∂m, (n·2, nx, ny, 1, 3)."""
            m = m.detach().requires_grad_(True)
            centres_now = guiding_centres(m)
            flat = centres_now.reshape(-1)
            grads = [
                torch.autograd.grad(flat[k], m, retain_graph=k + 1 < len(flat))[0]
                for k in range(len(flat))
            ]
            return centres_now.detach(), torch.stack(grads)

        magnetic = self._magnetic.to(state.device)
        smoother = _Smoother(self.film, SMOOTHING_LENGTHS * self.material.exchange_length, magnetic)

        def tangent(m, v):
            return v - m * (m * v).sum(-1, keepdim=True)

        def direction(m, v):
            """T P T v: the preconditioned field, in the plane normal to m."""
            return tangent(m, smoother.smooth(tangent(m, v)))

        def step(m, tau):
            """The field H' at m, the step's direction d = T P T H', and the drift [m]."""
            state.m = m
            h = self._field() * magnetic
            if not len(targets):
                return h, direction(m, h), 0.0
            now, grads = constraint_gradients(m)
            # the step m ← m + τ d moves X by τ ⟨∂X, d⟩, and d is linear in the multipliers
            # (T P T is symmetric): choose them to make that −½ the drift
            smoothed = torch.stack([direction(m, g) for g in grads])
            a_matrix = torch.einsum("aijkl,bijkl->ab", grads, smoothed)
            d_field = direction(m, h)
            drift = (now - goal).reshape(-1)
            rhs = -torch.einsum("aijkl,ijkl->a", grads, d_field) - 0.5 * drift / tau
            scale = torch.sqrt(torch.diagonal(a_matrix)).clamp(min=1e-300)
            lam = (
                torch.linalg.solve(a_matrix / scale[:, None] / scale[None, :], rhs / scale) / scale
            )
            return (
                h + torch.einsum("a,aijkl->ijkl", lam, grads),
                d_field + torch.einsum("a,aijkl->ijkl", lam, smoothed),
                float(drift.abs().max()),
            )

        def midpoint(m, d, tau):
            n2 = (d * d).sum(-1, keepdim=True)
            return ((4 - tau * tau * n2) * m + 4 * tau * d) / (4 + tau * tau * n2)

        started = time.perf_counter()
        tau_min, tau_max = 1e-13, 1e-5
        tau = tau_min
        m = state.m.detach().clone()
        h, d, drift = step(m, tau)
        dm = -tangent(m, h)
        converged, iterations = False, 0
        for iterations in range(1, max_iterations + 1):
            m_new = midpoint(m, d, tau)
            h_new, d_new, drift = step(m_new, tau)
            dm_new = -tangent(m_new, h_new)  # m × (m × H')
            torque = float(dm_new.abs().max())
            s_vec, y_vec = m_new - m, dm_new - dm
            # Barzilai–Borwein step sizes in P's metric, alternating
            if iterations % 2:
                tau = float((s_vec * smoother.sharpen(s_vec)).sum() / (s_vec * y_vec).sum())
            else:
                tau = float((s_vec * y_vec).sum() / (y_vec * smoother.smooth(y_vec)).sum())
            tau = min(max(abs(tau), tau_min), tau_max)
            m, h, d, dm = m_new, h_new, d_new, dm_new
            if torque < torque_tolerance and drift < 1e-3 * cell:
                converged = True
                break
        state.m = m
        energies = {name: float(term.E(state)) for name, term in self.terms.items()}
        return Relaxed(
            self._get(),
            energies,
            float(sum(energies.values())),
            iterations,
            converged,
            torque,
            time.perf_counter() - started,
        )

    def evolve(
        self,
        m0: np.ndarray,
        t0: float,
        duration: float,
        first_step: float = 1e-14,
        tolerance: float = 1e-5,
    ) -> Evolved:
        """Integrate the LLG equation from ``m0`` at time ``t0`` [s] for ``duration`` [s].

        At T = 0, without current, with the material's α and γ:

            ∂m/∂t = −γ' m × H_eff − αγ' m × (m × H_eff),   γ' = γμ₀/(1 + α²)

        by Runge–Kutta–Fehlberg 4(5) with absolute and relative ``tolerance``, starting with
        step ``first_step`` [s]. The result is a pure function of (m0, t0, first_step,
        duration): cut at the same times (the last step of a piece is shortened to end on
        time), a resumed integration is the same, bit for bit, as one left alone.
        """
        mn = backend()
        import torch

        self._set(m0)
        gamma = self.material.gyromagnetic_ratio * mn.constants.mu_0
        alpha = self.material.damping
        gamma_prime = gamma / (1.0 + alpha * alpha)
        terms = list(self.terms.values())
        state = self.state

        def rhs(t, m, state):
            state.t = t
            state.m = m
            h = sum(term.h(state) for term in terms)
            mxh = torch.linalg.cross(m, h)
            return -gamma_prime * mxh - alpha * gamma_prime * torch.linalg.cross(m, mxh)

        solver = mn.RKF45(rhs, dt=first_step, atol=tolerance, rtol=tolerance)
        started = time.perf_counter()
        steps0 = state._step
        t, m = solver.step(torch.tensor(float(t0)), state.m, duration, state=state)
        mn.normalize(m)
        state.m = m
        return Evolved(
            self._get(),
            float(t),
            float(solver._dt),
            state._step - steps0,
            time.perf_counter() - started,
        )


def skyrmion_texture(
    film: Film, centres, radius: float, wall_width: float, helicity: float = 0.0
) -> np.ndarray:
    """Skyrmions (core −z, background +z) at ``centres`` [(x, y), m] with the 360° wall profile.

    θ(r) = 2 atan[sinh(R/Δ)/sinh(r/Δ)], superposed as m = normalise(ẑ + Σ(mᵢ − ẑ)); ``helicity`` 0
    gives Néel walls (interfacial DMI), π/2 Bloch walls (bulk DMI). Shape (nx, ny, 3), zero outside
    a disk film.
    """
    x, y = film.centres()
    m = np.zeros((film.nx, film.ny, 3))
    m[..., 2] = 1.0
    for cx, cy in centres:
        dx, dy = x - cx, y - cy
        r = np.hypot(dx, dy)
        theta = 2 * np.arctan2(
            math.sinh(radius / wall_width), np.sinh(np.maximum(r, 1e-30) / wall_width)
        )
        phi = np.arctan2(dy, dx) + helicity
        m[..., 0] += np.sin(theta) * np.cos(phi)
        m[..., 1] += np.sin(theta) * np.sin(phi)
        m[..., 2] += np.cos(theta) - 1.0
    m /= np.linalg.norm(m, axis=-1, keepdims=True)
    return m * film.magnetic()[..., None]


def template_texture(
    film: Film, centres, radius, mz, helicity: float, scale: float = 1.0
) -> np.ndarray:
    """Skyrmions at ``centres`` [(x, y), m] with the measured profile m_z(r).

    The profile (``radius`` [m], ``mz``; +1 beyond the last radius) is stretched radially by
    ``scale``, with ``helicity`` [rad], and the skyrmions are superposed as in
    :func:`skyrmion_texture`.
    """
    x, y = film.centres()
    m = np.zeros((film.nx, film.ny, 3))
    m[..., 2] = 1.0
    radius, mz = np.asarray(radius, float), np.clip(np.asarray(mz, float), -1.0, 1.0)
    for cx, cy in centres:
        dx, dy = x - cx, y - cy
        cos_theta = np.interp(np.hypot(dx, dy) / scale, radius, mz, right=1.0)
        sin_theta = np.sqrt(np.maximum(1.0 - cos_theta**2, 0.0))
        phi = np.arctan2(dy, dx) + helicity
        m[..., 0] += sin_theta * np.cos(phi)
        m[..., 1] += sin_theta * np.sin(phi)
        m[..., 2] += cos_theta - 1.0
    m /= np.linalg.norm(m, axis=-1, keepdims=True)
    return m * film.magnetic()[..., None]
