"""Microscope movies of skyrmions: render simulated gases as movies, track skyrmions in movies.

- :mod:`skygas.movies.render`: a run's positions → a microscope-like TIFF stack (blur, noise,
  illumination drift), with its pixel size and frame interval recorded;
- :mod:`skygas.movies.reading`: a TIFF stack or folder of images in, checked;
- :mod:`skygas.movies.choices`: the tracker's settings chosen from the movie;
- :mod:`skygas.movies.tracking`: locate and link with trackpy, write the tracks in trackpy's
  format (``skygas track``, docs/tracking.md).
"""
