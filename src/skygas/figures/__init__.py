"""Figures of outlines, landscapes, trajectories and current flow (matplotlib, Agg backend).

Below the engine, so that :meth:`skygas.Simulation.plot` and every command's figures draw
with the same functions (:mod:`skygas.figures.plotting`).
"""
