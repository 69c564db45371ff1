"""How well tracks recovered known positions: localisation error, misses, false detections, links.

Used on movies rendered from simulations (:mod:`skygas.movies.render`), where every true
position is known: each true position is matched to the nearest detection of its frame
(within ``match_px``); the error of the matched ones, the true positions without a match
(missed), the detections matched to none (false) and, for every skyrmion seen in two
consecutive frames, whether both detections belong to the same track (a right link).
"""

from __future__ import annotations

import numpy as np

#: a true position with no detection closer than this is missed [px]
MATCH_PX = 1.5


def tracking_accuracy(table, truth, match_px: float = MATCH_PX) -> dict:
    """Compare trackpy's ``table`` with the true positions ``truth``.

    Parameters
    ----------
    table : pandas.DataFrame
        Tracks with ``frame``, ``particle``, ``x``, ``y`` [px].
    truth : sequence of (ids, x, y)
        Per frame (0, 1, …): the true skyrmions' ids and positions [px].
    match_px : float
        The farthest a detection may be from its true position [px].

    Returns
    -------
    dict
        ``positions`` (true, in all frames), ``missed``, ``false``, ``rms_px`` and ``bias_px``
        (x, y) of the matched detections, ``links_right`` and ``links_wrong``.
    """
    from scipy.spatial import cKDTree

    errors, missed, false, right, wrong, total = [], 0, 0, 0, 0, 0
    previous: dict = {}
    by_frame = dict(iter(table.groupby("frame")))
    for f, (ids, tx, ty) in enumerate(truth):
        here = by_frame.get(f, table.iloc[:0])
        total += len(ids)
        if not len(here):
            missed += len(ids)
            previous = {}
            continue
        dist, j = cKDTree(here[["x", "y"]].to_numpy()).query(np.column_stack([tx, ty]))
        ok = dist < match_px
        missed += int((~ok).sum())
        false += len(here) - int(ok.sum())
        x, y = here["x"].to_numpy()[j[ok]], here["y"].to_numpy()[j[ok]]
        errors.append(np.column_stack([x - tx[ok], y - ty[ok]]))
        particle = dict(zip(np.asarray(ids)[ok], here["particle"].to_numpy()[j[ok]], strict=True))
        for skyrmion, p in particle.items():
            if skyrmion in previous:
                right += int(previous[skyrmion] == p)
                wrong += int(previous[skyrmion] != p)
        previous = particle
    e = np.concatenate(errors) if errors else np.zeros((0, 2))
    return {
        "positions": total,
        "missed": missed,
        "false": false,
        "rms_px": np.sqrt(np.mean(e**2, axis=0)),
        "bias_px": e.mean(axis=0),
        "links_right": right,
        "links_wrong": wrong,
    }
