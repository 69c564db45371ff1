"""Design search: optuna finds the device configuration that meets a target, on Dask, resumable.

- :func:`~skygas.optimize.spec.load_study`: read and fully validate a study file (device and
  base configuration as in a sweep file, the search space, objectives, constraints, replicas);
- :func:`~skygas.optimize.execute.run_study`: run its trials (serially or on Dask) into a study
  folder, resuming what a previous invocation left;
- :func:`~skygas.optimize.results.write_results`: trials.csv, best.json, the Pareto front,
  optuna's figures and report.html from a study folder.

See ``docs/optimize.md``.
"""
