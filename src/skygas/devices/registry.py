"""The device registry: one :class:`DeviceKind` per kind of run, in :data:`KINDS`.

A kind is a command that runs a device (or a plain simulation) and writes a run folder:
``simulate``, ``reshuffle``, ``neuron``, ``reservoir``, ``saturation``. The code that serves
every kind (the report, ``skygas check-timestep``, the analysis) asks its kind here what it
needs, instead of switching on the kind's name; a new device adds one entry.

Importing this module is cheap: every field that needs a device's code (its headline, its
configuration model, its check-timestep builder) is a small function here that imports the
device only when called. The devices import nothing from here at module level but
:mod:`skygas.devices.timestep`'s helpers.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from skygas.core.errors import InputError
from skygas.devices.study_hooks import StudyPoints

if TYPE_CHECKING:
    from skygas.core.headline import Results
    from skygas.devices.records import RecordParts

#: a check-timestep builder: ``build(time_step, brownian_substeps)`` → the filled simulation
Build = Callable[[float | None, int], Any]


@dataclass(frozen=True)
class TimeStepCheck:
    """How ``skygas check-timestep`` reads and builds one kind's configuration.

    Attributes
    ----------
    markers : frozenset[str]
        The TOML tables or top-level keys only this kind's configuration has: a file with them
        (and none of another kind's) is this kind's (:func:`~skygas.commands.check_timestep.
        detect_device`).
    load : callable
        ``load(path, preset)`` → the validated configuration, as the kind's command reads it
        (``path`` None: its defaults). Raises :class:`InputError` where it has none.
    probe : callable
        ``probe(config)`` → ``(build, count)``: ``build(time_step, brownian_substeps)`` returns
        the device's simulation without its operations, filled as in use; ``count`` is the
        skyrmions placed (None where the configuration places its own).
    presets : bool
        Whether the kind takes ``--preset`` (the reshuffler's presets).
    """

    markers: frozenset[str]
    load: Callable[[str | None, str | None], Any]
    probe: Callable[[Any], tuple[Build, int | None]]
    presets: bool = False


@dataclass(frozen=True)
class RecordFile:
    """The result file of a run that recorded positions, as ``load_run`` reads it back.

    (:func:`skygas.outputs.records.load_run`: the movie, the analysis, the export.)

    Attributes
    ----------
    name : str
        Its file name in the run folder (``"reshuffler.nc"``).
    tells : callable
        ``tells(ds)`` → whether the opened dataset ``ds`` is this kind's file (its contents
        tell, not its name: a file may be given under any name).
    read : callable
        ``read(ds)`` → :class:`~skygas.devices.records.RecordParts`: the parts of the run that
        depend on the kind (imported when called).
    fallback : bool
        Whether it is the plain simulation's file (dense positions with their configuration),
        which a device's file may look like too: its ``tells`` is asked after the others'.
    """

    name: str
    tells: Callable[[Any], bool]
    read: Callable[[Any], RecordParts]
    fallback: bool = False


@dataclass(frozen=True)
class DeviceKind:
    """One kind of run: what the code serving every kind needs to know about it.

    Attributes
    ----------
    name : str
        The kind's name, as the command line and a folder's manifest write it (``"reshuffle"``).
    command : str
        The command that makes such a run (``"skygas reshuffle"``).
    title : str
        The title of its report (``report.html``).
    captions : Mapping[str, str]
        Captions of its figures, by file name, where they differ from the shared ones of
        :data:`skygas.outputs.report.FIGURE_CAPTIONS` (its ``device.png``).
    recorded_captions : Mapping[str, str]
        The same, for a run that recorded positions (its device figure draws trajectories).
    summary_keys : tuple[str, ...]
        Keys that only its summary has: they tell a folder without a manifest to be this kind's
        (each key belongs to one kind only, so the order of :data:`KINDS` does not matter).
    result_files : tuple[str, ...]
        Names of the result file it writes in place of ``summary.json`` (the reservoir's
        ``reservoir.json``), which tell its folders too.
    config_key : tuple[str, ...]
        Where its summary keeps the run's configuration (the reservoir's in ``device.config``).
    run_headline : callable or None
        ``run_headline(summary, config, analysis)`` → :class:`~skygas.core.headline.Results`:
        what the report of a run that recorded positions states first (None: the kind records
        none, or its report is a simulation's).
    folder_headline : callable or None
        ``folder_headline(summary, directory)`` → Results: the same for a folder that holds a
        summary but no positions (None: nothing before the summary's numbers).
    config_model : callable or None
        ``config_model()`` → the pydantic class of its configuration (imported when called).
    uniform_drive : bool
        Whether its drift is one uniform velocity (``skygas simulate``'s ``[drift]``), so that
        the angle of the mean velocity is the skyrmion Hall angle; a device's current follows
        its conduits and walls.
    occupancy_groups : callable or None
        ``occupancy_groups()`` → ``(group_of(x, y), names)``: how the occupancy of a recorded
        run counts its skyrmions per part of the device (None: all together).
    timestep : TimeStepCheck or None
        How ``skygas check-timestep`` checks it (None: it does not).
    record : RecordFile or None
        The result file of its runs that recorded positions (None: it writes none).
    study : StudyPoints or None
        How a study (``skygas sweep``, ``skygas optimize``) builds, prices and runs its points
        (None: it cannot be swept).
    cli : str
        ``"module:function"`` that adds its sub-command: ``function(subparsers, kind)`` names
        the parser ``kind.name`` (imported when the command line is built).
    help : str
        The one line its sub-command shows in ``skygas --help``.
    example : str
        An example command line, shown at the end of its ``--help``.
    """

    name: str
    command: str
    title: str
    captions: Mapping[str, str] = field(default_factory=dict)
    recorded_captions: Mapping[str, str] = field(default_factory=dict)
    summary_keys: tuple[str, ...] = ()
    result_files: tuple[str, ...] = ()
    config_key: tuple[str, ...] = ("config",)
    run_headline: Callable[[dict, dict, dict], Results] | None = None
    folder_headline: Callable[[dict, Path], Results] | None = None
    config_model: Callable[[], type[Any]] | None = None
    uniform_drive: bool = False
    occupancy_groups: Callable[[], tuple[Callable, tuple[str, ...]]] | None = None
    timestep: TimeStepCheck | None = None
    record: RecordFile | None = None
    study: StudyPoints | None = None
    cli: str = ""
    help: str = ""
    example: str = ""

    def caption(self, name: str, *, recorded: bool = False) -> str | None:
        """The caption of its figure ``name``, or None where it has no caption of its own."""
        if recorded and name in self.recorded_captions:
            return self.recorded_captions[name]
        return self.captions.get(name)

    def config_in(self, summary: dict) -> Any:
        """The run's configuration, read from its summary at :attr:`config_key` (or None)."""
        value: Any = summary
        for key in self.config_key:
            value = (value or {}).get(key)
        return value


# -- the kinds' parts that need their device's code (imported when called) -------------------
def _simulation_headline(summary: dict, config: dict, analysis: dict) -> Results:
    from skygas.runs.headline import simulation

    return simulation(summary, analysis)


def _reshuffler_headline(summary: dict, config: dict, analysis: dict) -> Results:
    from skygas.reshuffler.headline import reshuffler

    return reshuffler(summary, config)


def _neuron_run_headline(summary: dict, config: dict, analysis: dict) -> Results:
    from skygas.neuron.headline import neuron
    from skygas.runs.headline import diffusion_rows

    results = neuron(summary)
    diffusion_rows(results, analysis)  # a run recorded with --animate has the positions
    return results


def _neuron_folder_headline(summary: dict, directory: Path) -> Results:
    from skygas.neuron.headline import neuron

    return neuron(summary)


def _reservoir_headline(summary: dict, directory: Path) -> Results:
    from skygas.reservoir.headline import reservoir

    return reservoir(summary)


def _saturation_headline(summary: dict, directory: Path) -> Results:
    from skygas.neuron.headline import saturation

    return saturation(summary)


def _simulation_model() -> type[Any]:
    from skygas.runs.config import SimulationConfig

    return SimulationConfig


def _reshuffler_model() -> type[Any]:
    from skygas.reshuffler.config import ReshufflerConfig

    return ReshufflerConfig


def _neuron_model() -> type[Any]:
    from skygas.neuron.config import NeuronConfig

    return NeuronConfig


def _reservoir_model() -> type[Any]:
    from skygas.reservoir.config import ReservoirConfig

    return ReservoirConfig


def _reshuffler_chambers() -> tuple[Callable, tuple[str, ...]]:
    import numpy as np

    from skygas.reshuffler.device import CHAMBERS

    # the UP chamber lies above the x axis, DOWN below (the device's geometry)
    return (lambda x, y: np.where(y >= 0.0, 0, 1)), CHAMBERS


# check-timestep: each kind's reader and builder live with the kind (its ``timestep`` module;
# the plain simulation's in skygas.devices.timestep)
def _lazy(module: str, name: str) -> Callable[..., Any]:
    """``module.name``, imported when first called: importing the registry imports no device."""

    def call(*args: Any) -> Any:
        from importlib import import_module

        return getattr(import_module(module), name)(*args)

    call.__qualname__ = call.__name__ = f"{module}.{name}"
    return call


def _timestep_check(module: str, markers: set[str], presets: bool = False) -> TimeStepCheck:
    """A kind's :class:`TimeStepCheck`: its ``markers``, and ``module``'s ``load`` and ``probe``."""
    return TimeStepCheck(frozenset(markers), _lazy(module, "load"), _lazy(module, "probe"), presets)


# the result files of the runs that record positions: told by their contents, read by the kind
def _simulation_tells(ds: Any) -> bool:
    return "x" in ds and "config_json" in ds.attrs


def _reshuffler_tells(ds: Any) -> bool:
    return "snapshot_count" in ds


def _neuron_tells(ds: Any) -> bool:
    # skygas.neuron.records.write_frames writes the kind of the run that recorded the frames
    from skygas.neuron.records import RUN_KIND_ATTRIBUTE

    return ds.attrs.get(RUN_KIND_ATTRIBUTE) == "neuron"


_NEURON_DEVICE_PNG = (
    "The neuron over its energy landscape, with the skyrmions present at the end of the run "
    "(no trajectories: the run recorded no positions; --animate records them)."
)

#: Every kind, by name; the order is the one the command line lists them in.
KINDS: dict[str, DeviceKind] = {
    k.name: k
    for k in (
        DeviceKind(
            name="simulate",
            command="skygas simulate",
            title="Skyrmion gas simulation",
            summary_keys=("skyrmions_initial",),
            run_headline=_simulation_headline,
            config_model=_simulation_model,
            uniform_drive=True,
            timestep=_timestep_check(
                "skygas.devices.timestep",
                {"geometry", "skyrmions", "record_interval", "drift", "integrator"},
            ),
            record=RecordFile(
                "trajectories.nc",
                _simulation_tells,
                _lazy("skygas.devices.records", "simulation"),
                fallback=True,
            ),
            study=StudyPoints("skygas.runs.study_points"),
            cli="skygas.commands.simulate:register_kind",
            help="run a simulation described by a TOML file",
            example="skygas simulate examples/closed-chamber.toml --out out/chamber",
        ),
        DeviceKind(
            name="reshuffle",
            command="skygas reshuffle",
            title="Skyrmion Reshuffler",
            captions={
                "device.png": "The reshuffler: current density |j| in both chambers (colour), "
                "the walls, the read-out lines and the trajectories of the first skyrmions "
                "injected (their time span in the title)."
            },
            summary_keys=("correlation",),
            run_headline=_reshuffler_headline,
            config_model=_reshuffler_model,
            occupancy_groups=_reshuffler_chambers,
            timestep=_timestep_check(
                "skygas.reshuffler.timestep",
                {"preset", "signal", "output", "current", "hypothesis", "spin_polarization"},
                presets=True,
            ),
            record=RecordFile(
                "reshuffler.nc", _reshuffler_tells, _lazy("skygas.reshuffler.records", "record")
            ),
            study=StudyPoints("skygas.reshuffler.study_points"),
            cli="skygas.commands.reshuffle:register_kind",
            help="run the Skyrmion Reshuffler",
            example="skygas reshuffle --preset paper --duration 2e-6 --current-density 1.7e11 "
            "--out out/reshuffler",
        ),
        DeviceKind(
            name="neuron",
            command="skygas neuron",
            title="Skyrmion Neuron",
            # a neuron run draws trajectories only when it recorded positions (--animate)
            captions={"device.png": _NEURON_DEVICE_PNG},
            recorded_captions={
                "device.png": "The neuron over its energy landscape, with the recorded "
                "trajectories (start ○, end ●)."
            },
            summary_keys=("lif_fit",),
            run_headline=_neuron_run_headline,
            folder_headline=_neuron_folder_headline,
            config_model=_neuron_model,
            timestep=_timestep_check(
                "skygas.neuron.timestep",
                {
                    "gate",
                    "sensor",
                    "rule",
                    "annihilation",
                    "inputs",
                    "transfer",
                    "release_current_density",
                },
            ),
            record=RecordFile("frames.nc", _neuron_tells, _lazy("skygas.neuron.records", "record")),
            study=StudyPoints("skygas.neuron.study_points"),
            cli="skygas.commands.neuron:register_neuron",
            help="run the Skyrmion Neuron",
            example="skygas neuron examples/neuron.toml --out out/neuron",
        ),
        DeviceKind(
            name="reservoir",
            command="skygas reservoir",
            title="Brownian reservoir computing",
            summary_keys=("boolean",),
            result_files=("reservoir.json",),
            config_key=("device", "config"),  # the study keeps it with its device
            folder_headline=_reservoir_headline,
            config_model=_reservoir_model,
            timestep=_timestep_check(
                "skygas.reservoir.timestep",
                {
                    "chamber",
                    "drive",
                    "sensors",
                    "readout",
                    "study",
                    "n_skyrmions",
                    "hold_time",
                },
            ),
            study=StudyPoints("skygas.reservoir.study_points"),
            cli="skygas.commands.reservoir:register_kind",
            help="Brownian reservoir computing: Boolean functions and temporal tasks from one "
            "chamber",
            example="skygas reservoir --out out/reservoir --json",
        ),
        DeviceKind(
            name="saturation",
            command="skygas saturation",
            title="Maximum skyrmion density (saturation)",
            summary_keys=("diameters_m",),
            result_files=("saturation.json",),
            config_key=("parameters",),  # the protocol's settings: it has no configuration file
            folder_headline=_saturation_headline,
            cli="skygas.commands.neuron:register_saturation",
            help="maximum number of skyrmions in circular chambers",
            example="skygas saturation --diameters 300e-9 500e-9 --repetitions 3 "
            "--out out/saturation",
        ),
    )
}


def kind(name: str) -> DeviceKind:
    """The kind called ``name``.

    Raises
    ------
    InputError
        If no kind has that name (the message lists the known ones).
    """
    if name not in KINDS:
        raise InputError("device", name, f"one of {', '.join(KINDS)}")
    return KINDS[name]


#: The device of a study file that names none: sweep files were the reshuffler's first.
DEFAULT_STUDY_DEVICE = "reshuffler"


def study_kinds() -> dict[str, DeviceKind]:
    """The kinds a study can run, by every name a study file may call them."""
    found: dict[str, DeviceKind] = {}
    for k in KINDS.values():
        if k.study is not None:
            found[k.study.name] = k
            found.setdefault(k.name, k)
    return found


def study_kind(name: object, field: str = "sweep.device") -> DeviceKind:
    """The kind a study file names ``name`` (its study name or its command's name).

    Raises
    ------
    InputError
        Naming ``field``, if no kind that a study can run has that name.
    """
    kinds = study_kinds()
    if not isinstance(name, str) or name not in kinds:
        names = sorted({k.study.name for k in kinds.values() if k.study is not None})
        raise InputError(field, name, f"one of {', '.join(names)}")
    return kinds[name]


def recorded_kind(name: str) -> DeviceKind:
    """The kind whose report a run that recorded positions gets.

    Its own where it has a :attr:`~DeviceKind.run_headline`; a simulation's otherwise (``skygas
    demo``, which the registry does not know, writes a simulation's result file).
    """
    found = KINDS.get(name)
    return found if found is not None and found.run_headline is not None else KINDS["simulate"]


def record_files() -> tuple[str, ...]:
    """The names of the result files of runs that recorded positions, in :data:`KINDS`' order.

    (The order a run folder is searched in.)
    """
    return tuple(k.record.name for k in KINDS.values() if k.record is not None)


def kind_of_record(ds: Any) -> DeviceKind | None:
    """The kind whose result file the opened dataset ``ds`` is, or None where none tells it.

    A device's file is told by what only it has; the plain simulation's (the
    :attr:`RecordFile.fallback`), which a device's file may look like, is tried last.
    """
    records = [(k, k.record) for k in KINDS.values() if k.record is not None]
    for k, record in sorted(records, key=lambda pair: pair[1].fallback):  # stable: KINDS' order
        if record.tells(ds):
            return k
    return None


def kind_of_summary(summary: dict, directory: Path, file_name: str | None = None) -> str | None:
    """The command that wrote the results in ``directory``, or None where it cannot be told.

    The command its manifest names (any command, ``"sc demo"`` too); without a manifest, the
    kind whose result file ``file_name`` (the summary's file) is, else the kind whose keys
    ``summary`` has.
    """
    from skygas.runs import manifest

    found = manifest.read(directory) or {}
    if found.get("command"):
        return str(found["command"])
    for k in KINDS.values():
        if file_name in k.result_files:
            return k.name
    return next(
        (k.name for k in KINDS.values() if any(key in summary for key in k.summary_keys)), None
    )
