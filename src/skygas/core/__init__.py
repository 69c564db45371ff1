"""Foundations (layer 1, docs/architecture.md), importing nothing else of skygas.

The unit system, the one error every bad input gets, checks of values handed to the API, the strict
base of every configuration, the set-up memo and its disk cache, the size checks made before
anything is allocated, and the rows a report states first (`headline`).
"""
