"""Linking detected skyrmions of successive snapshots into trajectories.

Frame to frame, live trajectories and new detections are matched by minimum total displacement
(the linear assignment problem, solved exactly by scipy's Hungarian-type solver), with a gate:
a link longer than ``max_step`` [m] is forbidden. A detection left unmatched starts a new
trajectory (a skyrmion that appears: nucleation or entry); a trajectory left unmatched for more
than ``memory`` frames ends (annihilation or exit). ``memory`` > 0 bridges frames in which a
skyrmion was missed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from skygas.core.errors import InputError
from skygas.micromag.detection import Skyrmion, Snapshot


@dataclass
class Trajectory:
    """One skyrmion over time.

    ``frames`` (snapshot indices), ``times`` [s], ``positions`` (n, 2) [m], and per frame ``radius``
    [m], ``charge`` and ``dissipation``.
    """

    id: int
    frames: list[int] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    points: list[Skyrmion] = field(default_factory=list)

    def add(self, frame: int, time: float, skyrmion: Skyrmion) -> None:
        """Append ``skyrmion`` as seen in snapshot ``frame`` at ``time`` [s]."""
        self.frames.append(frame)
        self.times.append(time)
        self.points.append(skyrmion)

    @property
    def positions(self) -> np.ndarray:
        """Centres (n, 2) [m], one per frame."""
        return np.array([[p.x, p.y] for p in self.points]).reshape(-1, 2)

    @property
    def radius(self) -> np.ndarray:
        """Radius [m] per frame."""
        return np.array([p.radius for p in self.points])

    @property
    def charge(self) -> np.ndarray:
        """Topological charge Q per frame."""
        return np.array([p.charge for p in self.points])

    @property
    def dissipation(self) -> np.ndarray:
        """Dissipation 𝒟 per frame (dimensionless)."""
        return np.array([p.dissipation for p in self.points])

    def __len__(self) -> int:
        return len(self.frames)


def link(
    snapshots: list[Snapshot], max_step: float, memory: int = 0, times=None
) -> list[Trajectory]:
    """Trajectories through ``snapshots`` (in time order), see the module docstring.

    ``times`` [s] overrides the snapshots' own times (e.g. from a user-given interval).
    """
    if not max_step > 0:
        raise InputError("max_step", max_step, "a distance > 0 in metres")
    if memory < 0:
        raise InputError("memory", memory, "a number of frames >= 0")
    if times is None:
        times = [s.time for s in snapshots]
    if len(times) != len(snapshots):
        raise InputError("times", len(times), f"{len(snapshots)} times, one per snapshot")
    finished: list[Trajectory] = []
    live: list[Trajectory] = []
    next_id = 0
    for frame, (snap, time) in enumerate(zip(snapshots, times, strict=True)):
        detections = list(snap.skyrmions)
        matched_tracks: set[int] = set()
        matched_dets: set[int] = set()
        if live and detections:
            last = np.array([t.positions[-1] for t in live])
            now = np.array([[s.x, s.y] for s in detections])
            cost = np.linalg.norm(last[:, None, :] - now[None, :, :], axis=-1)
            big = 1e6 * max_step + cost.max()
            rows, cols = linear_sum_assignment(np.where(cost <= max_step, cost, big))
            for r, c in zip(rows, cols, strict=True):
                if cost[r, c] <= max_step:
                    live[r].add(frame, float(time), detections[c])
                    matched_tracks.add(r)
                    matched_dets.add(c)
        still_live = []
        for index, track in enumerate(live):
            if index in matched_tracks or frame - track.frames[-1] <= memory:
                still_live.append(track)
            else:
                finished.append(track)
        live = still_live
        for index, skyrmion in enumerate(detections):
            if index not in matched_dets:
                track = Trajectory(next_id)
                track.add(frame, float(time), skyrmion)
                live.append(track)
                next_id += 1
    return sorted(finished + live, key=lambda t: t.id)
