"""Magnetoresistive read-out: the fraction of each sensor's area that skyrmions cover.

A skyrmion is a disk of radius R_sk whose core is reversed; a sensor is a disk of radius r_s
under which a magnetoresistive signal measures the reversed area. The signal of sensor s is

    c_s = Σ_i A(|x_i − s|; R_sk, r_s) / (π r_s²)   (+ Gaussian read noise, std ``read_noise``)

with A(d; R, r) the overlap area of two disks whose centres are d apart (exact lens formula).
"""

from __future__ import annotations

import numpy as np


def disk_overlap_area(d, r1: float, r2: float) -> np.ndarray:
    """Area of the intersection of two disks of radii ``r1``.

    ``r2`` whose centres are ``d`` apart (any length unit; the area in that unit squared).
    """
    d = np.asarray(d, float)
    small, big = min(r1, r2), max(r1, r2)
    out = np.zeros(d.shape)
    inside = d <= big - small
    out[inside] = np.pi * small**2
    lens = (d > big - small) & (d < r1 + r2)
    x = d[lens]
    a1 = r1**2 * np.arccos(np.clip((x * x + r1 * r1 - r2 * r2) / (2 * x * r1), -1, 1))
    a2 = r2**2 * np.arccos(np.clip((x * x + r2 * r2 - r1 * r1) / (2 * x * r2), -1, 1))
    k = (-x + r1 + r2) * (x + r1 - r2) * (x - r1 + r2) * (x + r1 + r2)
    out[lens] = a1 + a2 - 0.5 * np.sqrt(np.maximum(k, 0.0))
    return out


def coverage(
    x_nm: np.ndarray,
    y_nm: np.ndarray,
    centers_nm: np.ndarray,
    sensor_radius_nm: float,
    skyrmion_radius_nm: float,
) -> np.ndarray:
    """Covered fraction of each sensor, (frames, sensors).

    From positions (frames, slots) [nm] (NaN for empty slots).
    """
    out = np.empty((x_nm.shape[0], len(centers_nm)))
    area = np.pi * sensor_radius_nm**2
    for s, (cx, cy) in enumerate(centers_nm):
        d = np.hypot(x_nm - cx, y_nm - cy)
        d = np.where(np.isfinite(d), d, np.inf)
        out[:, s] = disk_overlap_area(d, sensor_radius_nm, skyrmion_radius_nm).sum(axis=1) / area
    return out
