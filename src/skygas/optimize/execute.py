"""Running a study: ask the optimiser for trials, run their replicas, tell it the results.

The study lives in its folder ``DIR``:

- ``study.json``: the study's description, its file's text and fingerprint (a folder only
  resumes the study that made it, as a sweep store);
- ``journal.log``: optuna's journal storage (:class:`optuna.storages.JournalStorage`), one
  appended line per change, so a killed client loses at most the line being written;
- ``runs/trial-K/replica-R.json``: each finished run's summary quantities, written as the run
  arrives (``reeval-R.json`` for the re-evaluation's runs);
- ``trials/N/summary.json``: each finished trial: its parameters, seeds, every run's
  quantities, the objectives' and constraints' means and standard errors, its state.

Trials are asked several at once (as many runs in flight as there are workers) through
optuna's ask-and-tell interface and told as their last replica arrives; the sampler is TPE
(``constant_liar``: trials still running count as bad, so parallel trials spread out), NSGA-II,
the Gaussian-process sampler or random sampling, all seeded from the study's seed.

Resuming (the same command again): finished trials are kept as they are. A trial that was
running when the client died is marked failed in the journal and asked again with the same
parameters (``rerun_of``): its runs have the same seeds (they derive from the trial it reruns)
and the runs that had finished are read back from ``runs/``, not run again. ``--trials K``
counts finished trials (complete, or failed with an error) in all, so ``--trials 60`` after
``--trials 40`` runs 20 more. The sampler is seeded anew from the study's seed and the number of
trials already in the journal, so a resumed study never replays the proposals it started with
(the serial path of a study that is never interrupted is reproducible from its seed).
"""

from __future__ import annotations

import json
import math
import os
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skygas._version import __version__
from skygas.core.errors import InputError, require
from skygas.core.estimates import Estimate, announce_pending, check
from skygas.optimize.spec import MAX_TRIALS, Study
from skygas.optimize.worker import run_trial
from skygas.runs.progress import count_bar

STUDY_FILE = "study.json"
JOURNAL = "journal.log"
RUNS = "runs"
TRIALS = "trials"
#: optuna's name of the study in the journal
STUDY_NAME = "skygas-optimize"
#: the study folder's kind, in study.json
KIND = "skygas optimize study"


def is_study_folder(path: str | Path) -> bool:
    """Whether ``path`` is a study folder (holds a ``study.json`` of :data:`KIND`)."""
    try:
        return json.loads((Path(path) / STUDY_FILE).read_text()).get("kind") == KIND
    except (OSError, ValueError, AttributeError):
        return False


def read_study_record(path: str | Path) -> dict:
    """The ``study.json`` of study folder ``path``."""
    return json.loads((Path(path) / STUDY_FILE).read_text())


def open_folder(out: str | Path, study: Study) -> Path:
    """Check that ``out`` is new, empty or this study's folder; record the study in a new one.

    Raises
    ------
    InputError
        For a folder of another study file, another command's results or other files.
    """
    from skygas.runs import manifest
    from skygas.runs.run_driver import write_json

    out = Path(out)
    found = manifest.read(out)
    if found is not None and found.get("command") != "optimize":
        raise InputError(
            "--out",
            str(out),
            f"a folder for `skygas optimize` studies (it holds the results of "
            f"`skygas {found.get('command')}`)",
            "choose another --out",
        )
    if (out / STUDY_FILE).exists():
        record = read_study_record(out)
        require(
            record.get("fingerprint") == study.fingerprint(),
            "--out",
            str(out),
            "a study folder made from this study file (it holds a study of another file, "
            "seed or settings)",
            "choose another --out, or run the study file (and --seed) that made it",
        )
        return out
    visible = [p.name for p in out.iterdir() if not p.name.startswith(".")] if out.is_dir() else []
    require(
        not visible,
        "--out",
        str(out),
        f"a new or empty folder, or a study folder (it holds {', '.join(sorted(visible)[:3])})",
        "choose another --out",
    )
    out.mkdir(parents=True, exist_ok=True)
    record = {
        "kind": KIND,
        "skygas_version": __version__,
        "fingerprint": study.fingerprint(),
        "created_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        **study.describe(),
        "reevaluate": study.reevaluate,
        "reevaluate_replicas": study.reevaluate_replicas,
        "study_file": study.source_text,
    }
    write_json(out / STUDY_FILE, record)
    return out


def constraint_values(trial) -> list[float]:
    """The violations a trial recorded (≤ 0: met), for optuna's Pareto-front figure.

    The samplers read the same values, set with :meth:`optuna.trial.Trial.set_constraint`.
    """
    return list(trial.user_attrs["constraints"])


def make_sampler(study: Study, n_existing: int):
    """The study's sampler, seeded from the study's seed and the trials already there."""
    import optuna

    seed = int(np.random.SeedSequence([study.seed, n_existing, 2]).generate_state(1)[0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        if study.sampler == "tpe":
            return optuna.samplers.TPESampler(
                seed=seed,
                n_startup_trials=study.startup_trials,
                constant_liar=True,
            )
        if study.sampler == "nsga2":
            return optuna.samplers.NSGAIISampler(
                seed=seed,
                population_size=max(2, study.startup_trials),
            )
        if study.sampler == "gp":
            return optuna.samplers.GPSampler(seed=seed, n_startup_trials=study.startup_trials)
        return optuna.samplers.RandomSampler(seed=seed)


def repair_journal(path: Path) -> None:
    """Drop a last line that a killed client left half-written (never acknowledged).

    optuna reads such a line as the end of the journal but would append the next line to it.
    """
    if not path.exists():
        return
    with path.open("rb+") as f:
        data = f.read()
        if data and not data.endswith(b"\n"):
            f.truncate(data.rfind(b"\n") + 1)


def open_optuna(out: Path, study: Study, *, sampler: bool = True):
    """The optuna study in ``out``'s journal (created when new)."""
    import optuna
    from optuna.storages import JournalStorage
    from optuna.storages.journal import JournalFileBackend

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    repair_journal(out / JOURNAL)
    storage = JournalStorage(JournalFileBackend(str(out / JOURNAL)))
    directions: list[Any] = [o.direction for o in study.objectives]
    existing = len(storage.get_all_studies())
    n_trials = 0
    if existing:
        n_trials = len(storage.get_all_trials(storage.get_study_id_from_name(STUDY_NAME)))
    return optuna.create_study(
        storage=storage,
        study_name=STUDY_NAME,
        directions=directions,
        sampler=make_sampler(study, n_trials) if sampler else None,
        load_if_exists=True,
    )


def finished_count(trials) -> int:
    """Trials that count towards ``--trials``: complete, or failed with a recorded error."""
    from optuna.trial import TrialState

    return sum(
        t.state == TrialState.COMPLETE or (t.state == TrialState.FAIL and "error" in t.user_attrs)
        for t in trials
    )


def _recover(ostudy, names) -> int:
    """Mark the trials that were running when a client died failed, and ask them again.

    A trial killed while it was being asked, before every parameter (``names``) had been
    drawn and stored, has no point to repeat: it is failed, and the sampler draws afresh.
    """
    from optuna.trial import TrialState

    interrupted = ostudy.get_trials(deepcopy=False, states=(TrialState.RUNNING,))
    for t in interrupted:
        ostudy.tell(t.number, state=TrialState.FAIL, skip_if_finished=True)
        if set(t.params) == set(names):
            ostudy.enqueue_trial(
                dict(t.params), user_attrs={"rerun_of": t.user_attrs.get("rerun_of", t.number)}
            )
    return len(interrupted)


def _mean_error(values: list[float]) -> tuple[float, float]:
    """The mean and its standard error (NaN with one value)."""
    a = np.asarray(values, dtype=float)
    if len(a) == 0 or not np.all(np.isfinite(a)):
        return math.nan, math.nan
    error = float(a.std(ddof=1) / math.sqrt(len(a))) if len(a) > 1 else math.nan
    return float(a.mean()), error


def aggregate(study: Study, runs: list[dict[str, float]]) -> dict[str, Any]:
    """Objectives and constraints over ``runs``: each one's mean and its standard error.

    An objective is evaluated on each run, then averaged; a constraint's violation likewise.
    """
    out: dict[str, Any] = {"objectives": {}, "constraints": {}}
    for o in study.objectives:
        mean, error = _mean_error([o.expression(r) for r in runs])
        out["objectives"][o.name] = {"mean": mean, "error": error}
    for c in study.constraints:
        mean, error = _mean_error([c.expression(r) for r in runs])
        violation, _ = _mean_error([c.violation(r) for r in runs])
        out["constraints"][c.text] = {
            "mean": mean,
            "error": error,
            "violation": violation,
            "met": bool(violation <= 0),
        }
    out["quantities"] = {
        name: dict(zip(("mean", "error"), _mean_error([r[name] for r in runs]), strict=True))
        for name in study.device.quantities
    }
    return out


# -- executors ----------------------------------------------------------------------------
class _Serial:
    """Runs each submitted run in this process when its result is asked for."""

    capacity = 1

    def __init__(self) -> None:
        self.queue: list[tuple[Any, str, str]] = []

    @property
    def in_flight(self) -> int:
        return len(self.queue)

    def submit(self, tag, device: str, config_json: str) -> None:
        self.queue.append((tag, device, config_json))

    def next(self) -> tuple[Any, dict | None, str | None]:
        tag, device, config_json = self.queue.pop(0)
        try:
            return tag, run_trial(device, config_json), None
        except Exception as err:  # noqa: BLE001 - a failed run fails its trial, not the study
            return tag, None, f"{type(err).__name__}: {err}"

    def close(self) -> None:
        pass


class _Dask:
    """Runs on a Dask client: a local cluster of ``workers`` processes or a scheduler's."""

    def __init__(self, client, workers: int | None) -> None:
        from dask.distributed import Client, as_completed

        from skygas.runs.cluster import start_local_cluster

        self.cluster = None
        if client is None:
            self.cluster = start_local_cluster(workers or os.cpu_count() or 1)
            client = Client(self.cluster)
        self.client = client
        threads = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
        self.capacity = max(1, workers if self.cluster is not None and workers else threads)
        self.futures: dict[Any, Any] = {}
        # on this client's event loop (see skygas.sweep.execute._dask)
        self.completed = as_completed([], loop=client.loop)

    @property
    def in_flight(self) -> int:
        return len(self.futures)

    def submit(self, tag, device: str, config_json: str) -> None:
        future = self.client.submit(
            run_trial,
            device,
            config_json,
            pure=False,
            key=f"skygas-trial-{tag[0]}-{tag[1]}-{tag[2]}-{time.time_ns()}",
        )
        self.futures[future] = tag
        self.completed.add(future)

    def next(self) -> tuple[Any, dict | None, str | None]:
        future = next(self.completed)
        tag = self.futures.pop(future)
        try:
            return tag, future.result(), None
        except Exception as err:  # noqa: BLE001 - a failed run fails its trial, not the study
            return tag, None, f"{type(err).__name__}: {err}"
        finally:
            future.release()

    def close(self) -> None:
        import logging

        self.client.close()
        if self.cluster is not None:
            # a worker slow to exit on a loaded machine is killed, as it should be: not news
            logging.getLogger("distributed.nanny").setLevel(logging.ERROR)
            self.cluster.close()


# -- the loop -----------------------------------------------------------------------------
@dataclass
class _Trial:
    """A trial in progress: optuna's trial, its seed key, configurations and runs so far."""

    trial: Any
    key: int
    seeds: list[int]
    configs: list[str]
    results: dict[int, dict] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return len(self.results) + len(self.errors) == len(self.seeds)


def run_file(out: Path, key: int, replica: int, stage: str = "replica") -> Path:
    """Where run ``replica`` of trial ``key`` keeps its quantities.

    ``stage`` ``"reeval"``: the trial's re-evaluation runs.
    """
    return out / RUNS / f"trial-{key}" / f"{stage}-{replica}.json"


def _read_run(path: Path) -> dict | None:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return {k: (math.nan if v is None else float(v)) for k, v in data["quantities"].items()}


def _write_run(path: Path, device: str, seed: int, config_json: str, quantities: dict) -> None:
    from skygas.runs.run_driver import write_json

    path.parent.mkdir(parents=True, exist_ok=True)
    write_json(
        path,
        {
            "device": device,
            "seed": seed,
            "skygas_version": __version__,
            "config": json.loads(config_json),
            "quantities": quantities,
        },
    )


@dataclass
class OptimizeReport:
    """What one invocation did: trials finished now, found done, recovered, and its time."""

    out: Path
    finished_now: int = 0
    already: int = 0
    recovered: int = 0
    failed: list[tuple[int, str]] = field(default_factory=list)
    reevaluated: int = 0
    wall_time_s: float = 0.0


def _distributions(study: Study) -> dict:
    return {p.field: p.distribution() for p in study.parameters}


def _start_trial(study: Study, out: Path, ostudy, executor, active: dict) -> _Trial:
    trial = ostudy.ask(_distributions(study))
    key = int(trial.user_attrs.get("rerun_of", trial.number))
    seeds = study.run_seeds(key, study.replicas)
    pending = _Trial(trial, key, seeds, [])
    try:
        pending.configs = [study.config(trial.params, s).model_dump_json() for s in seeds]
    except InputError as err:  # a point inside the space that the device refuses
        pending.errors = [str(err)] * len(seeds)
    active[trial.number] = pending
    for r, config_json in enumerate(pending.configs):
        found = _read_run(run_file(out, key, r))
        if found is not None:  # a run of an interrupted trial that had finished
            pending.results[r] = found
        else:
            executor.submit((trial.number, r, "replica"), study.device.name, config_json)
    return pending


def _finish_trial(study: Study, out: Path, ostudy, pending: _Trial) -> str | None:
    """Tell optuna the trial's result; write its summary. Returns its error, if any."""
    from optuna.trial import TrialState

    from skygas.runs.run_driver import write_json

    trial = pending.trial
    runs = [pending.results[r] for r in sorted(pending.results)]
    summary: dict[str, Any] = {
        "number": trial.number,
        "seed_key": pending.key,
        "params": dict(trial.params),
        "seeds": pending.seeds,
        "skygas_version": __version__,
        "runs": runs,
    }
    error = pending.errors[0] if pending.errors else None
    values: list[float] = []
    if error is None:
        agg = aggregate(study, runs)
        summary.update(agg)
        values = [agg["objectives"][o.name]["mean"] for o in study.objectives]
        if not all(math.isfinite(v) for v in values):
            error = "an objective has no value (NaN): " + ", ".join(
                o.name
                for o, v in zip(study.objectives, values, strict=True)
                if not math.isfinite(v)
            )
        if study.constraints:
            violations = [agg["constraints"][c.text]["violation"] for c in study.constraints]
            # no value (a run without read-outs): the constraint is not met
            violations = [v if math.isfinite(v) else math.inf for v in violations]
            trial.set_user_attr("constraints", violations)
            for c, v in zip(study.constraints, violations, strict=True):
                trial.set_constraint(c.text, v)  # what the samplers read
        trial.set_user_attr(
            "objective_errors", [agg["objectives"][o.name]["error"] for o in study.objectives]
        )
    summary["state"] = "FAIL" if error else "COMPLETE"
    summary["error"] = error
    path = out / TRIALS / str(trial.number) / "summary.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_json(path, summary)
    if error:
        trial.set_user_attr("error", error)
        ostudy.tell(trial, state=TrialState.FAIL)
    else:
        ostudy.tell(trial, values)
    return error


def _drive(
    study: Study,
    out: Path,
    ostudy,
    executor,
    target: int,
    report: OptimizeReport,
    bar,
) -> None:
    active: dict[int, _Trial] = {}
    done = finished_count(ostudy.get_trials(deepcopy=False))
    while True:
        while done + len(active) < target and executor.in_flight < executor.capacity:
            pending = _start_trial(study, out, ostudy, executor, active)
            if pending.complete:  # every run read back, or refused: nothing to wait for
                break
        finished = [n for n, p in active.items() if p.complete]
        if not finished:
            if not active:
                return
            (number, replica, _), result, error = executor.next()
            pending = active[number]
            if error is not None:
                pending.errors.append(error)
            else:
                assert result is not None
                pending.results[replica] = result
                _write_run(
                    run_file(out, pending.key, replica),
                    study.device.name,
                    pending.seeds[replica],
                    pending.configs[replica],
                    result,
                )
            finished = [number] if pending.complete else []
        for number in finished:
            error = _finish_trial(study, out, ostudy, active.pop(number))
            done += 1
            report.finished_now += 1
            if error:
                report.failed.append((number, error))
            if bar is not None:
                bar.update(1)


def candidates(study: Study, ostudy) -> list:
    """The trials to re-evaluate: the ``reevaluate`` best complete ones meeting the constraints.

    With several objectives: members of the Pareto set, in trial order.
    """
    from optuna.trial import TrialState

    def feasible(t) -> bool:
        return all(v <= 0 for v in t.user_attrs.get("constraints", []))

    complete = [
        t for t in ostudy.get_trials(deepcopy=False, states=(TrialState.COMPLETE,)) if feasible(t)
    ]
    if study.multi_objective:
        pareto = {t.number for t in ostudy.best_trials}
        return [t for t in complete if t.number in pareto][: study.reevaluate]
    sign = 1.0 if study.objectives[0].direction == "minimize" else -1.0
    return sorted(complete, key=lambda t: sign * t.values[0])[: study.reevaluate]


def _reevaluate(
    study: Study, out: Path, ostudy, executor, report: OptimizeReport, progress: bool
) -> None:
    """Run the best candidates again (new seeds), keeping each run in ``runs/``."""
    # each run's configuration is built as it is handed out: only those in flight are held
    todo: list[tuple[tuple[int, int, str], int, dict]] = []
    for t in candidates(study, ostudy):
        key = int(t.user_attrs.get("rerun_of", t.number))
        seeds = study.run_seeds(key, study.reevaluate_replicas, stage=1)
        for r, seed in enumerate(seeds):
            if not run_file(out, key, r, "reeval").exists():
                todo.append(((key, r, "reeval"), seed, t.params))
    if not todo:
        return
    bar = count_bar(progress, len(todo), unit="run", desc="re-evaluate")
    configs: dict[tuple[int, int, str], tuple[int, str]] = {}
    queue = todo[::-1]  # popped from the end, in order
    try:
        while queue or executor.in_flight:
            while queue and executor.in_flight < executor.capacity:
                tag, seed, params = queue.pop()
                config_json = study.config(params, seed).model_dump_json()
                configs[tag] = (seed, config_json)
                executor.submit(tag, study.device.name, config_json)
            tag, result, error = executor.next()
            if error is not None:
                configs.pop(tag)
                report.failed.append((tag[0], f"re-evaluation run {tag[1]}: {error}"))
            else:
                seed, config_json = configs.pop(tag)
                _write_run(
                    run_file(out, tag[0], tag[1], "reeval"),
                    study.device.name,
                    seed,
                    config_json,
                    result,
                )
                report.reevaluated += 1
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()


#: Wall time [s] the study spends on each run besides the run itself: optuna's ask and tell,
#: the journal's lines and the run's files (12 analytic trials took 0.4 s, serial).
RUN_OVERHEAD_SECONDS = 0.02
#: Memory [bytes] the study holds per trial (optuna's record of it: parameters, attributes,
#: distributions) and per re-evaluation run waiting for a worker.
TRIAL_BYTES = 16 * 2**10
WAITING_RUN_BYTES = 512


def study_runs(study: Study, trials: int, done: int = 0) -> tuple[int, int]:
    """(runs of ``trials`` trials, re-evaluation runs at most) of ``study``.

    ``done`` trials are finished already: their best may be re-evaluated too.
    """
    candidates = min(study.reevaluate, done + trials)
    return trials * study.replicas, candidates * study.reevaluate_replicas


def check_study(study: Study, trials: int, workers: int, done: int = 0) -> Estimate:
    """Refuse a study that cannot fit or finish; announce a long one (:mod:`skygas.core.estimates`).

    ``trials`` still to run (``done`` already finished) on ``workers`` processes. Each run is
    priced as its device prices one (:attr:`~skygas.optimize.devices.Device.estimate`), half of
    them at the space's lowest corner (every parameter at its low end or first choice) and half
    at its highest; the re-evaluation runs count as the trials' own.
    """
    low = study.config({p.field: p.ends()[0] for p in study.parameters})
    high = study.config({p.field: p.ends()[-1] for p in study.parameters})
    one = [study.device.estimate(c) for c in (low, high)]
    trial_runs, reevaluation_runs = study_runs(study, trials, done)
    runs = trial_runs + reevaluation_runs
    parallel = max(1, min(workers, runs))
    per_run = 0.5 * (one[0].seconds + one[1].seconds) + RUN_OVERHEAD_SECONDS
    memory = (
        parallel * max(e.memory for e in one)
        + (done + trials) * TRIAL_BYTES
        + reevaluation_runs * WAITING_RUN_BYTES
    )
    steps = max(e.steps for e in one)
    estimate = Estimate(steps, memory, runs * per_run / parallel, runs=max(1, runs))
    check(
        estimate,
        "study",
        f"{trial_runs} runs of {trials} trials + {reevaluation_runs} re-evaluation runs",
        f"{runs} runs on {parallel} workers",
        "run fewer --trials, replicas or re-evaluations (reevaluate × reevaluate_replicas), "
        "or shorter runs",
    )
    announce_pending()  # the study is accepted: its estimate, if it is long, now
    return estimate


def _finished_before(out: Path, study: Study) -> int:
    """Trials already finished in ``out`` if it is this study's folder (0 otherwise)."""
    if not (is_study_folder(out) and (out / JOURNAL).exists()):
        return 0
    if read_study_record(out).get("fingerprint") != study.fingerprint():
        return 0  # another study's folder: open_folder refuses it
    return finished_count(open_optuna(out, study, sampler=False).get_trials(deepcopy=False))


def run_study(
    study: Study,
    out: str | Path,
    trials: int,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    serial: bool = False,
    progress: bool = True,
) -> OptimizeReport:
    """Run ``study`` in folder ``out`` until ``trials`` trials have finished.

    Then re-evaluate its best candidates (see the module docstring).

    ``serial=True`` runs in this process, one run at a time; otherwise on Dask: a local cluster
    of ``workers`` single-threaded processes (default: one per core), or the scheduler at
    ``scheduler``.
    """
    from skygas.runs.cluster import connect

    require(
        1 <= trials <= MAX_TRIALS, "--trials", trials, f"a number of trials from 1 to {MAX_TRIALS}"
    )
    require(workers is None or workers >= 1, "--workers", workers, "at least 1 worker")
    start = time.perf_counter()
    # the estimate before anything is written: a refused study leaves its folder as it was
    done = _finished_before(Path(out), study)
    parallel = 1 if serial else workers or os.cpu_count() or 1
    check_study(study, max(0, trials - done), parallel, done)
    out = open_folder(out, study)
    ostudy = open_optuna(out, study)
    report = OptimizeReport(out)
    report.recovered = _recover(ostudy, _distributions(study))
    report.already = finished_count(ostudy.get_trials(deepcopy=False))
    client = connect(scheduler) if scheduler is not None and not serial else None
    executor: _Serial | _Dask = _Serial() if serial else _Dask(client, workers)
    bar = count_bar(progress, trials, report.already, unit="trial", desc="optimize")
    try:
        _drive(study, out, ostudy, executor, trials, report, bar)
        if bar is not None:
            bar.close()
            bar = None
        if study.reevaluate:
            _reevaluate(study, out, ostudy, executor, report, progress)
    finally:
        if bar is not None:
            bar.close()
        executor.close()
    report.wall_time_s = time.perf_counter() - start
    return report


def iter_trial_summaries(out: Path) -> Iterator[dict]:
    """The ``trials/N/summary.json`` of folder ``out``, in trial order."""
    folder = out / TRIALS
    numbers = (
        sorted(int(p.name) for p in folder.iterdir() if p.name.isdigit()) if folder.is_dir() else []
    )
    for n in numbers:
        path = folder / str(n) / "summary.json"
        if path.exists():
            yield json.loads(path.read_text())


def reevaluation_runs(out: Path, key: int) -> list[dict]:
    """The re-evaluation runs of trial ``key`` kept in ``out`` (in replica order)."""
    folder = out / RUNS / f"trial-{key}"
    if not folder.is_dir():
        return []
    paths = sorted(folder.glob("reeval-*.json"), key=lambda p: int(p.stem.split("-")[1]))
    return [r for r in (_read_run(p) for p in paths) if r is not None]
