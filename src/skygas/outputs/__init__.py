"""What a finished run leaves to look at and to take elsewhere.

- :mod:`~skygas.outputs.records`: any run's result file read back as one :class:`RunRecord`
  (frames, device outline, skyrmion size, provenance);
- :mod:`~skygas.outputs.movie`: MP4 (or GIF) movies of the gas;
- :mod:`~skygas.outputs.report`: one self-contained HTML report;
- :mod:`~skygas.outputs.headlines`: what each command's report states first (its results, with
  errors and units, named through :mod:`skygas.core.quantities`);
- :mod:`~skygas.outputs.export`: GSD and extended-XYZ trajectories for particle viewers;
- :mod:`~skygas.outputs.finish`: what every run command calls once its results are written.
"""
