"""How well ``skygas track`` recovered the shipped movie's skyrmions: error, misses, links.

Compares the tracks (``tracks.csv``, pixels) with the simulation the movie was rendered from
(``trajectories.nc``, metres; the movie's sidecar JSON gives its pixel grid) and prints the
localisation error (RMS per axis and bias, pixels and nm), the missed and false detections and
the fraction of frame-to-frame steps linked to the right skyrmion.

Run from the repository's root, after ``sh examples/tracking/make-movie.sh`` and
``skygas track examples/tracking/chamber-movie.tif --out out/track``::

    python examples/tracking/compare_tracks.py out/tracking-gas out/track/tracks.csv \
        examples/tracking/chamber-movie.json
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import pandas as pd

from skygas.movies.accuracy import tracking_accuracy
from skygas.outputs.records import load_run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="the simulation's folder (trajectories.nc)")
    parser.add_argument("tracks", help="tracks.csv of skygas track")
    parser.add_argument("sidecar", help="the movie's sidecar JSON")
    args = parser.parse_args()
    meta = json.loads(open(args.sidecar).read())
    p, (x0, y0) = meta["pixel_size_m"], meta["origin_m"]
    stride = meta.get("stride", 1)
    frames = load_run(args.run).frames
    first = int(np.searchsorted(frames.time, meta["first_time_s"] * (1 - 1e-9)))
    table = pd.read_csv(args.tracks)
    truth = []
    for f in range(int(meta["shape"][0])):
        ids, xy = frames.frame(first + f * stride)
        truth.append((ids, (xy[:, 0] - x0) / p, (xy[:, 1] - y0) / p))
    a = tracking_accuracy(table, truth)
    rms, bias = a["rms_px"], a["bias_px"]
    total, missed, false, right, wrong = (
        a[k] for k in ("positions", "missed", "false", "links_right", "links_wrong")
    )
    n = len(truth)
    print(f"{total} true positions in {n} frames; {missed} missed, {false} false detections")
    print(
        f"localisation error RMS x, y = {rms[0]:.3f}, {rms[1]:.3f} px "
        f"({rms[0] * p * 1e9:.2f}, {rms[1] * p * 1e9:.2f} nm); "
        f"bias {bias[0]:+.4f}, {bias[1]:+.4f} px"
    )
    print(f"steps linked right: {right} of {right + wrong} ({100 * right / (right + wrong):.3f} %)")


if __name__ == "__main__":
    main()
