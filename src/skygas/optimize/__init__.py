"""Design search: optuna finds the device configuration that meets a target, on Dask, resumable.

- :func:`~skygas.optimize.spec.load_study`: read and fully validate a study file (device and
  base configuration as in a sweep file, the search space, objectives, constraints, replicas);
- :func:`~skygas.optimize.execute.run_study`: run its trials (serially or on Dask) into a study
  folder, resuming what a previous invocation left;
- :func:`~skygas.optimize.results.write_results`: trials.csv, best.json, the Pareto front,
  the figures (:mod:`~skygas.optimize.figures`) and report.html
  (:mod:`~skygas.optimize.report`) from a study folder;
- :mod:`~skygas.optimize.verdict`: the best trial chosen on its re-evaluation runs, the
  candidates within noise of it, its parameters on a search bound, and the statement of all
  that which the terminal and the report share.

See ``docs/optimize.md``.
"""
