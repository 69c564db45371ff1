"""Fields on a grid over an outline (layer 3, docs/architecture.md).

The distance and normal to the walls, the current flow and its spin drift, the energy landscape
(:mod:`skygas.fields.landscape`) and the bilinear lookup of the engine's packed field grid.
"""
