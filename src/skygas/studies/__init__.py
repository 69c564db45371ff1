"""Studies: many runs of a device (or a calibration) over points, replicas and searches.

:mod:`skygas.studies.backend` is their one parallel backend (Dask).
"""
