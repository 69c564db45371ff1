"""What a run records: frames of positions, exits through ports, and the trajectories Dataset.

The kernel records frames itself, into one block per call (:class:`FrameBlock`), so a run does
not return to Python for every frame; exits arrive in batches
(:class:`~skygas.engine.exit_log.ExitLog`). The recorder keeps both, turns them into an xarray
Dataset on request (:meth:`Recorder.trajectories`), and saves and restores them exactly for
checkpoints (raw arrays, no unit conversion, no Dataset).
"""

from __future__ import annotations

import json
from typing import NamedTuple

import numpy as np

from skygas._version import __version__
from skygas.core import units
from skygas.engine.exit_log import ExitLog
from skygas.engine.kernel import Exits, Frames
from skygas.engine.store import by_id


class FrameBlock(NamedTuple):
    """The frames one kernel call recorded: ``f`` frames of the ``slots`` storage slots it saw.

    ``x``, ``y`` [nm] are NaN and ``ids`` is −1 where a slot was empty. The id in a slot can
    change from frame to frame (a skyrmion leaves, a new one is inserted in its slot).
    """

    step: np.ndarray  # (f,) global step numbers
    time: np.ndarray  # (f,) [s]
    x: np.ndarray  # (f, slots) [nm]
    y: np.ndarray  # (f, slots) [nm]
    ids: np.ndarray  # (f, slots)
    r: np.ndarray | None = None  # (f, slots) [nm]: a breathing model's radii (else None)

    def positions(self, f: int) -> tuple[np.ndarray, np.ndarray]:
        """Frame ``f`` as :meth:`Simulation.positions` gives the live state.

        (ids, positions [m] of shape (n, 2)) of the skyrmions present, ordered by id.
        """
        present = self.ids[f] >= 0
        return by_id(self.ids[f][present], self.x[f][present], self.y[f][present])


class Recorder:
    """Frame blocks and exits of one run, and the kernel's buffers for them."""

    def __init__(self, port_names) -> None:
        self.port_names = list(port_names)
        self.blocks: list[FrameBlock] = []
        #: the step of the last frame recorded (−1: none yet), kept when frames are taken
        self.last_frame_step = -1
        self.exits = ExitLog(self.port_names)
        self._no_frames: Frames | None = None
        self._exit_buffer: Exits | None = None

    # -- buffers for one kernel call ---------------------------------------------------------
    def frame_buffer(self, n_frames: int, slots: int, capacity: int, radii: bool = False) -> Frames:
        """Room for ``n_frames`` frames of ``slots`` slots (and their radii, if ``radii``).

        When there are none, a dummy sized for the store's ``capacity`` (reused while it stays the
        same).
        """
        if n_frames:
            return Frames(
                np.empty((n_frames, slots)),
                np.empty((n_frames, slots)),
                np.empty((n_frames, slots), dtype=np.int64),
                np.empty((n_frames, slots) if radii else (0, 0)),
            )
        if self._no_frames is None or self._no_frames.x.shape[1] != capacity:
            self._no_frames = Frames(
                np.empty((1, capacity)),
                np.empty((1, capacity)),
                np.empty((1, capacity), dtype=np.int64),
                np.empty((1, capacity)),
            )
        return self._no_frames

    def exit_buffer(self, most: int) -> Exits:
        """Room for at least ``most`` exits, reused while large enough.

        The reshuffler makes ~10⁴ kernel calls, and allocating for each would cost more than short
        calls.
        """
        buf = self._exit_buffer
        if buf is None or len(buf.ids) < most:
            size = max(most, 2 * (len(buf.ids) if buf is not None else 0), 1)
            buf = self._exit_buffer = Exits(
                np.empty(size, np.int64),
                np.empty(size, np.int64),
                np.empty(size, np.int64),
                np.empty(size),
                np.empty(size),
            )
        return buf

    # -- what a call recorded ----------------------------------------------------------------
    def add_exits(self, buf: Exits, n: int, time_step: float) -> None:
        """Log the first ``n`` exits of a kernel call's ``buf`` (steps to seconds, nm to m)."""
        if n:
            self.exits.append(
                buf.ids[:n],
                buf.step[:n] * time_step,
                buf.port[:n],
                buf.x[:n] / units.M_TO_NM,
                buf.y[:n] / units.M_TO_NM,
            )

    def add_frames(
        self, frames: Frames, recorded: int, first_step: int, every: int, time_step: float
    ) -> None:
        """Keep the first ``recorded`` frames of a call, the first at ``first_step``."""
        if recorded:
            steps = first_step + every * np.arange(recorded, dtype=np.int64)
            self.last_frame_step = int(steps[-1])
            radii = frames.r[:recorded] if frames.r.shape == frames.x.shape else None
            self.blocks.append(
                FrameBlock(
                    steps,
                    steps * time_step,
                    frames.x[:recorded],
                    frames.y[:recorded],
                    frames.ids[:recorded],
                    radii,
                )
            )

    def take_frames(self, first_block: int = 0) -> list[FrameBlock]:
        """Remove and return the blocks from index ``first_block`` on."""
        taken = self.blocks[first_block:]
        del self.blocks[first_block:]
        return taken

    # -- results -----------------------------------------------------------------------------
    def trajectories(self, attrs: dict, parameters: dict):
        """Recorded positions as a Dataset (see :meth:`Simulation.trajectories`).

        With ``attrs`` and the JSON of ``parameters`` as its attributes.
        """
        blocks = self.blocks
        times = np.concatenate([b.time for b in blocks]) if blocks else np.empty(0)
        # one column per skyrmion seen in a frame (a run that nucleates 10⁵ skyrmions but
        # records only its first microsecond has a few hundred)
        seen = (
            np.unique(np.concatenate([b.ids[b.ids >= 0] for b in blocks]))
            if blocks
            else np.empty(0, dtype=np.int64)
        )
        x = np.full((len(times), len(seen)), np.nan)
        y = np.full((len(times), len(seen)), np.nan)
        breathing = any(b.r is not None for b in blocks)
        radius = np.full((len(times), len(seen)), np.nan) if breathing else None
        row = 0
        for block in blocks:
            frame, slot = np.nonzero(block.ids >= 0)
            column = np.searchsorted(seen, block.ids[frame, slot])
            x[row + frame, column] = block.x[frame, slot] / units.M_TO_NM
            y[row + frame, column] = block.y[frame, slot] / units.M_TO_NM
            if radius is not None and block.r is not None:
                radius[row + frame, column] = block.r[frame, slot] / units.M_TO_NM
            row += len(block.time)
        ex = self.exits.arrays()
        # imported here: a run that records no trajectory (a sweep's worker) never needs it
        import xarray as xr

        ds = xr.Dataset(
            {
                "x": (("time", "skyrmion"), x, {"units": "m", "long_name": "x position"}),
                "y": (("time", "skyrmion"), y, {"units": "m", "long_name": "y position"}),
                "exit_skyrmion": ("exit", ex["skyrmion"].copy()),
                "exit_time": ("exit", ex["time"].copy(), {"units": "s"}),
                "exit_port": ("exit", self.exits.port_labels()),
            },
            coords={"time": ("time", times, {"units": "s"}), "skyrmion": seen.astype(np.int64)},
        )
        if radius is not None:
            ds["radius"] = (
                ("time", "skyrmion"),
                radius,
                {"units": "m", "long_name": "skyrmion radius"},
            )
        ds.attrs.update(
            {
                "title": "skygas skyrmion trajectories",
                "skygas_version": __version__,
                **attrs,
                "parameters_json": json.dumps(parameters),
            }
        )
        return ds

    # -- checkpoints -------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """Frames and exits as raw arrays (bit-exact, no Dataset)."""
        blocks = self.blocks
        widths = np.array([b.x.shape[1] for b in blocks], dtype=np.int64)
        lengths = np.array([len(b.step) for b in blocks], dtype=np.int64)

        def flat(name: str, dtype) -> np.ndarray:
            if not blocks:
                return np.empty(0, dtype)
            return np.concatenate([getattr(b, name).ravel() for b in blocks])

        ex = self.exits.arrays()
        return {
            "frame_widths": widths,
            "frame_lengths": lengths,
            "frame_step": flat("step", np.int64),
            "frame_time": flat("time", float),
            "frame_x": flat("x", float),
            "frame_y": flat("y", float),
            "frame_ids": flat("ids", np.int64),
            **({"frame_r": flat("r", float)} if any(b.r is not None for b in blocks) else {}),
            "frame_last_step": np.array(self.last_frame_step, dtype=np.int64),
            **{f"exit_{k}": v.copy() for k, v in ex.items()},
        }

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore the frames and exits of :meth:`state_dict`."""
        self.blocks = []
        row = cell = 0
        for width, length in zip(state["frame_widths"], state["frame_lengths"], strict=True):
            cells = slice(cell, cell + width * length)
            rows = slice(row, row + length)
            self.blocks.append(
                FrameBlock(
                    state["frame_step"][rows].copy(),
                    state["frame_time"][rows].copy(),
                    state["frame_x"][cells].reshape(length, width).copy(),
                    state["frame_y"][cells].reshape(length, width).copy(),
                    state["frame_ids"][cells].reshape(length, width).copy(),
                    state["frame_r"][cells].reshape(length, width).copy()
                    if "frame_r" in state
                    else None,
                )
            )
            row += length
            cell += width * length
        last = state.get("frame_last_step")
        self.last_frame_step = int(last) if last is not None else -1
        self.exits = ExitLog(self.port_names)
        self.exits.append(
            state["exit_skyrmion"],
            state["exit_time"],
            state["exit_port"],
            state["exit_x"],
            state["exit_y"],
        )
