"""The calibration as a run-driver job: solves on Dask workers, checkpoints, resume.

:class:`CalibrationJob` follows :class:`skygas.runs.run_driver.Job`. Its *work* is the planned
solves, weighted by their expected cost; each piece of the job waits (at most a second) for
solves to finish, records them and hands new ones to idle workers: the processes of a local
Dask cluster, or a running cluster's (:mod:`skygas.calibration.cluster`). What can run depends
on what has finished (:mod:`skygas.calibration.plan`): the isolated skyrmion first, then, once
its diameter is known, the laws, the checks and the validation run, whose LLG pieces form a
chain (each starts from the previous one's texture). The LLG chain goes first whenever it
can: it is the longest sequence of work.

The checkpoint holds every finished solve (energies, statistics, kept textures) and the LLG
run's state; a resumed calibration recomputes only the solves that were in flight, and since
every solve is a pure function of its inputs the results are the same, bit for bit.
"""

from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from skygas.calibration import plan
from skygas.calibration.plan import CalibrationConfig, Relaxation
from skygas.calibration.solver import Film
from skygas.core.state_keys import nest, unnest
from skygas.runs.run_driver import from_json_array, json_array

if TYPE_CHECKING:
    from distributed import Future

    from skygas.calibration.cluster import SolverPool

#: The stages as the progress bar names them, by the first part of their solves' names.
STAGE_NAMES = {
    "isolated": "isolated skyrmion",
    "laws": "pair and edge laws",
    "enlarged": "film-size check",
    "sensitivity": "field sensitivity and breathing scan",
    "shifted": "laws at a second radius",
    "stray": "edge stray field",
    "mesh": "mesh check",
    "validation": "validation start",
    "llg": "validation run (LLG)",
}
#: d ln R/dB [1/T] that sizes the breathing solves' cost before the sensitivity is measured
#: (their films do not depend on it, only their fields do).
NOMINAL_SLOPE = -10.0
#: LLG snapshots per piece of the validation run.
SNAPSHOTS_PER_PIECE = 5

#: the files whose presence means a finished calibration
RESULT_FILES: tuple[str, ...] = ("model.toml", "summary.json", "report.html")


class CalibrationJob:
    """A calibration (``config``) by ``workers`` processes of ``threads`` torch threads each.

    The processes are a local Dask cluster's, or, with ``scheduler`` (an address,
    ``tcp://HOST:PORT``), the workers of the Dask scheduler there. ``workers`` = 0 (and no
    scheduler): in this process, one solve per piece, as on a GPU.
    """

    #: work is the planned relaxations' and LLG pieces' estimated cost (about one unit per
    #: isolated-skyrmion relaxation), a number that means nothing to a user: the bar shows
    #: the percentage and the times only
    work_unit = "cost"
    progress_format = "{desc}{percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]"
    result_files = RESULT_FILES

    def __init__(
        self,
        config: CalibrationConfig,
        workers: int = 2,
        threads: int = 1,
        scheduler: str | None = None,
    ):
        self.config = config
        self.workers = int(workers)
        self.threads = int(threads)
        self.scheduler = scheduler
        self.material_json = config.material.model_dump_json()
        self.results: dict[str, dict[str, Any]] = {}
        self.textures: dict[str, np.ndarray] = {}
        self.llg: dict[str, Any] = {
            "frames": [],
            "time": 0.0,
            "next_step": 1e-14,
            "seconds": 0.0,
            "steps": 0,
            "finished": False,
        }
        self.llg_m: np.ndarray | None = None
        #: stage -> [first start, last end], in seconds of the run clock (:meth:`run_seconds`)
        self.timeline: dict[str, list[float]] = {}
        #: wall time of the run so far: its earlier sessions' (checkpointed), then this one's
        self._seconds_before = 0.0
        self._session_start: float | None = None
        #: solves finished before this session began (:attr:`rate_measured`)
        self._results_before = 0
        self._pool: SolverPool | None = None
        self._in_flight: dict[str, Future] = {}
        self._measured: dict[str, tuple | None] = {}
        #: the last solve handed out or recorded (its stage names the progress bar)
        self._last_key = "isolated"

    @property
    def work_description(self) -> str:
        """The progress bar's label: the stage being solved (``calibrating: mesh check``)."""
        key = next(iter(self._in_flight), self._last_key)
        stage = key.split("/")[0]
        return f"calibrating: {STAGE_NAMES.get(stage, stage)}"

    # -- what is known ------------------------------------------------------------------------
    def _stage1(self) -> tuple[list[Relaxation], Relaxation | None]:
        """Stage 1's solves so far, and its final single (None until known).

        The film grows until it is large enough for the radius measured in it, each larger film
        starting from the profile relaxed in the one before.
        """
        solves: list[Relaxation] = []
        radius, template = None, None
        while True:
            film = plan.isolated_film(self.config, radius)
            stage = plan.isolated_stage(self.config, f"isolated/{film.nx}", film, template)
            solves += stage.solves
            single_task = stage.solves[-1]
            single = self.results.get(single_task.name)
            if single is None or f"{stage.name}/uniform" not in self.results:
                return solves, None
            if len(single["skyrmions"]) != 1:
                return solves, single_task  # no isolated skyrmion: finish() refuses
            radius = single["skyrmions"][0]["radius"]
            if plan.ISOLATED_MIN_SIDE * radius <= film.size[0]:
                return solves, single_task
            template = self._measure(single_task)[2]

    def isolated_prefix(self) -> str | None:
        """The stage-1 solves whose result is final (``PREFIX/single``, ``PREFIX/uniform``)."""
        single = self._stage1()[1]
        return None if single is None else single.name.rsplit("/", 1)[0]

    def isolated_film(self) -> Film:
        """The final stage-1 film."""
        single = self._stage1()[1]
        assert single is not None, "stage 1 is not final yet"
        return single.film

    def isolated_size(self) -> tuple[float, float, plan.Template] | None:
        """(radius, wall width [m], starting template) of the isolated skyrmion.

        Once stage 1 is final and holds one skyrmion; None before.
        """
        single = self._stage1()[1]
        return None if single is None else self._measure(single)

    def _measure(self, task: Relaxation):
        """(radius, wall width, template) of a stage-1 single (None without one skyrmion).

        Kept, since the plan asks for it at every piece.
        """
        if task.name not in self._measured:
            result = self.results[task.name]
            self._measured[task.name] = None
            if len(result["skyrmions"]) == 1:
                from skygas.calibration.profile import fit_wall_width, helicity, radial_profile

                s, film = result["skyrmions"][0], task.film
                m = self.textures[task.name]
                r_max = min(0.5 * min(film.size) - film.cell_size, 6 * s["radius"])
                radii, mz = radial_profile(m, film, (s["x"], s["y"]), r_max)
                template = plan.Template(
                    tuple(map(float, radii)),
                    tuple(map(float, mz)),
                    helicity(m, film, (s["x"], s["y"])),
                )
                self._measured[task.name] = (
                    s["radius"],
                    fit_wall_width(radii, mz, s["radius"]),
                    template,
                )
        return self._measured[task.name]

    def planned(self) -> list[Relaxation]:
        """Every relaxation planned so far (it grows as results come in)."""
        config = self.config
        solves, _ = self._stage1()
        size = self.isolated_size()
        if size is not None:
            radius, width, template = size
            isolated = self.isolated_film()
            solves += plan.sized_solves(config, radius, width, template, isolated)
            slope = self.field_slope()
            if slope is not None:
                solves += plan.breathing_solves(config, radius, width, template, isolated, slope)
        return solves

    def field_slope(self) -> float | None:
        """The isolated skyrmion's d ln R/dB [1/T], once its sensitivity solves are done.

        It plans the breathing scan and the laws at a second radius.
        """
        size = self.isolated_size()
        if size is None:
            return None
        return plan.measured_slope(
            self.results.get("sensitivity/plus"), self.results.get("sensitivity/minus"), size[0]
        )

    def _isolated_radius(self) -> float:
        """The isolated skyrmion's radius [m], once known."""
        size = self.isolated_size()
        assert size is not None, "the isolated skyrmion is not known yet"
        return size[0]

    def validation_film(self) -> Film:
        """The validation disk's film, for the isolated skyrmion's diameter."""
        return plan.validation_film(self.config, 2 * self._isolated_radius())

    # -- the LLG chain ------------------------------------------------------------------------
    def _llg_piece_cost(self) -> float:
        film = self.validation_film()
        v = self.config.validation
        # an LLG step's explicit-stability limit scales as cell²; ~7 LLG snapshots of 50 ps
        # on 20 000 cells of 2 nm take as long as one relaxation
        scale = (2e-9 / self.config.material.cell_size) ** 2
        return (
            film.nx
            * film.ny
            / 20_000
            * scale
            * SNAPSHOTS_PER_PIECE
            * v.snapshot_interval
            / 50e-12
            / 7.0
        )

    def _llg_pieces_left(self) -> int:
        if not self.config.validate_dynamics or self.llg["finished"]:
            return 0
        v = self.config.validation
        total = math.ceil(v.max_duration / (SNAPSHOTS_PER_PIECE * v.snapshot_interval) - 1e-9)
        done = len(self.llg["frames"]) // SNAPSHOTS_PER_PIECE
        return max(total - done, 0)

    def _llg_travel_done(self) -> bool:
        """True once every skyrmion has travelled ``min_travel`` diameters (or one was lost)."""
        from skygas.calibration.validation import path_lengths

        frames = self.llg["frames"]
        if not frames:
            return False
        radius = self._isolated_radius()
        start = self.results["validation/start"]["skyrmions"]
        lengths = path_lengths(start, frames, 2 * radius)
        if lengths is None:  # a skyrmion was lost: nothing more to compare
            return True
        return min(lengths) >= self.config.validation.min_travel

    def _llg_task(self):
        v = self.config.validation
        if self.llg_m is None:
            self.llg_m = self.textures["validation/start"]
        args = (
            self.material_json,
            self.validation_film(),
            self.llg_m,
            self.llg["time"],
            self.llg["next_step"],
            SNAPSHOTS_PER_PIECE * v.snapshot_interval,
            v.snapshot_interval,
            v.llg_tolerance,
        )
        return f"llg/{len(self.llg['frames'])}", "evolve", args

    # -- the run-driver protocol --------------------------------------------------------------
    @property
    def work_total(self) -> float:
        """The estimated cost of every solve planned so far, and of what cannot be planned yet."""
        costs = sum(s.cost for s in self.planned())
        size = self.isolated_size()
        if size is None:
            costs += 60.0  # the laws, checks and validation, before they can be planned
        elif self.field_slope() is None:  # the breathing solves, before they can be planned
            radius, width, template = size
            nominal = plan.breathing_solves(
                self.config, radius, width, template, self.isolated_film(), NOMINAL_SLOPE
            )
            costs += sum(s.cost for s in nominal)
        elif self.config.validate_dynamics and "validation/start" in self.results:
            costs += self._llg_pieces_left() * self._llg_piece_cost() + self._llg_done_cost()
        return costs

    def _llg_done_cost(self) -> float:
        return len(self.llg["frames"]) // SNAPSHOTS_PER_PIECE * self._llg_piece_cost()

    def work_done(self) -> float:
        """The estimated cost of the solves done so far."""
        done = sum(s.cost for s in self.planned() if s.name in self.results)
        if self.config.validate_dynamics and "validation/start" in self.results:
            done += self._llg_done_cost()
        return done

    def _ready(self) -> list[tuple[str, str, tuple]]:
        """Tasks that can start now: the LLG chain and its start, then the costliest relaxations.

        The longest first: the least idle time at the end.
        """
        tasks = []
        if (
            self.config.validate_dynamics
            and "validation/start" in self.results
            and not self.llg["finished"]
            and not any(k.startswith("llg/") for k in self._in_flight)
        ):
            tasks.append(self._llg_task())
        pending = [
            s
            for s in self.planned()
            if s.name not in self.results and s.name not in self._in_flight
        ]
        # the validation's start first (the LLG chain waits for it), then the field
        # sensitivity (the breathing solves wait for it), then the costliest
        first = ("sensitivity/plus", "sensitivity/minus")
        for s in sorted(
            pending, key=lambda s: (s.name != "validation/start", s.name not in first, -s.cost)
        ):
            tasks.append((s.name, "relax", (self.material_json, s, self.config.torque_tolerance)))
        return tasks

    #: solves that must finish in a session before the progress bar shows a remaining time
    RATE_SOLVES = 2

    @property
    def rate_measured(self) -> bool:
        """Whether this session has finished :data:`RATE_SOLVES` solves.

        Until then the progress bar shows no remaining time, and it measures its rate from that
        point on: the workers' start-up (imports, the first solver's set-up) is not work, and a
        rate from the first cheap solve alone projected an hour for a five-minute calibration.
        """
        if self._session_start is None:  # not started (or resumed, not yet going)
            return False
        return len(self.results) - self._results_before >= self.RATE_SOLVES

    def run_seconds(self) -> float:
        """Wall time spent running, over all sessions [s].

        An interrupted and resumed run does not count the time it was stopped (the solves lost with
        the interruption count twice).
        """
        if self._session_start is None:
            return self._seconds_before
        return self._seconds_before + time.perf_counter() - self._session_start

    def advance_piece(self) -> None:
        """Start what can start and record what finished, returning within about a second.

        With no workers, one task is solved in this process instead.
        """
        from skygas.calibration import worker

        if self._session_start is None:
            self._session_start = time.perf_counter()
            self._results_before = len(self.results)

        if self.workers == 0 and self.scheduler is None:  # in this process (a GPU)
            from skygas.calibration import solver

            solver.configure(threads=os.cpu_count() or 1, compile=self.config.compile)
            ready = self._ready()
            if ready:
                key, kind, args = ready[0]
                self._record(key, getattr(worker, kind)(*args))
            return
        pool = self.connect()
        ready = self._ready()
        room = pool.capacity() - len(self._in_flight)
        for rank, (key, kind, args) in enumerate(ready[: max(room, 0)]):
            # the order of _ready() is the order Dask starts them in, should they queue
            priority = len(ready) - rank
            self._in_flight[key] = pool.submit_solve(
                key, kind, args, self._threads_for(kind, len(ready)), self.config.compile, priority
            )
            self._last_key = key
        deadline = time.perf_counter() + 1.0  # return within a second: Ctrl-C is honoured
        while time.perf_counter() < deadline:
            finished = [k for k, r in self._in_flight.items() if r.done()]
            if finished:
                for key in finished:
                    self._record(key, pool.result(self._in_flight.pop(key)))
                return
            time.sleep(0.02)

    def _threads_for(self, kind: str, ready: int) -> int:
        """Torch threads of a solve about to start.

        ``threads``, except for an LLG piece that a local cluster runs alone (nothing else
        ready or in flight): the LLG chain is the calibration's longest and runs one piece at
        a time, so once the relaxations are done it takes every worker's threads, up to the
        machine's cores. A relaxation planned while it runs shares the cores for one piece.
        A running cluster's workers keep ``threads``: their cores are not this machine's.
        """
        if kind != "evolve" or self.scheduler is not None or ready > 1 or self._in_flight:
            return self.threads
        return max(self.threads, min(self.workers * self.threads, os.cpu_count() or 1))

    def connect(self) -> SolverPool:
        """The Dask client of the solves: the scheduler's (``scheduler``), or a local cluster's.

        Made on the first call; a scheduler that does not answer is refused in one line
        (:class:`~skygas.core.errors.InputError` naming ``--scheduler``).
        """
        if self._pool is None:
            from skygas.calibration.cluster import SolverPool

            if self.scheduler is not None:
                self._pool = SolverPool.remote(self.scheduler)
            else:
                self._pool = SolverPool.local(self.workers)
        return self._pool

    def _record(self, key: str, result: dict[str, Any]) -> None:
        self._last_key = key
        stage = key.split("/")[0]
        now = self.run_seconds()
        began = max(0.0, now - result.get("seconds", 0.0))
        span = self.timeline.setdefault(stage, [began, now])
        span[0] = min(span[0], began)
        span[1] = now
        if key.startswith("llg/"):
            self.llg_m = result["m"]
            self.llg["frames"] += result["frames"]
            self.llg.update(time=result["time"], next_step=result["next_step"])
            self.llg["seconds"] += result["seconds"]
            self.llg["steps"] += result["steps"]
            if self._llg_travel_done() or self._llg_pieces_left() == 0:
                self.llg["finished"] = True
            return
        texture = result.pop("m", None)
        if texture is not None:
            self.textures[key] = texture
        self.results[key] = result

    def close(self) -> None:
        """Stop the workers and close the Dask client.

        A local cluster's workers stop at once: a solve in flight is recomputed on resume.
        """
        self._in_flight.clear()
        if self._pool is not None:
            pool, self._pool = self._pool, None
            pool.close()

    def state_dict(self) -> dict[str, np.ndarray]:
        """The results, LLG chain, timeline, run time and kept textures, as arrays."""
        state = {
            "results": json_array(self.results),
            "llg": json_array(self.llg),
            "timeline": json_array(self.timeline),
            "run_seconds": np.array(self.run_seconds()),
        }
        state.update(nest("texture:", self.textures))
        if self.llg_m is not None:
            state["llg_m"] = self.llg_m
        return state

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`state_dict` saved (the run clock restarts from its total)."""
        self.results = from_json_array(state["results"])
        self.llg = from_json_array(state["llg"])
        self.timeline = from_json_array(state["timeline"])
        self._seconds_before = float(state["run_seconds"])
        self._session_start = None
        self.textures = {k: np.asarray(v) for k, v in unnest("texture:", state).items()}
        self.llg_m = np.asarray(state["llg_m"]) if "llg_m" in state else None

    def config_json(self) -> str:
        """The validated configuration as JSON."""
        return self.config.model_dump_json()

    def seed(self) -> int:
        """The seed of the configuration (a calibration draws nothing at random)."""
        return self.config.seed()

    def finish(self, out_dir: Path):
        """Stop the workers, then analyse the results and write the files into ``out_dir``.

        Returns the data of ``summary.json``.
        """
        self.close()
        from skygas.calibration.results import write_results

        return write_results(self, Path(out_dir))


def dump_raw(job: CalibrationJob, path: Path) -> None:
    """The raw results as JSON (for debugging and the benchmark)."""
    path.write_text(
        json.dumps(
            {"results": job.results, "llg": job.llg, "timeline": job.timeline},
            default=float,
            indent=1,
        )
    )
