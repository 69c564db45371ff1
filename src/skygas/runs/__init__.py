"""Runs (layer 5, docs/architecture.md): what every run of a command shares.

The simulation's TOML configuration, the run driver (progress, checkpoints, Ctrl-C, ``--resume``),
the output folder's manifest, the sanity checks, the time-step check, the ``skygas simulate`` job
and the figures of outlines, landscapes, current flow and trajectories.
"""
