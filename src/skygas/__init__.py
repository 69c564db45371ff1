"""skygas: stochastic Thiele simulation of magnetic skyrmion gases and skyrmionic devices.

The public API:

- materials: :func:`preset`, :func:`load_material`, :class:`Material`, :func:`derive_thiele`,
  :class:`ThieleParameters`;
- geometry: :func:`disk`, :func:`rectangle`, :func:`polygon`, :func:`union`,
  :func:`chamber_with_conduits`, :class:`Outline`;
- the engine: :class:`Simulation`;
- configuration files: :func:`load_config`, :class:`SimulationConfig`, :func:`run_simulation`;
- errors: :class:`InputError`.

Sub-packages: :mod:`skygas.sc` (stochastic computing), :mod:`skygas.micromag` (micromagnetic
bridge), :mod:`skygas.analysis` (MSD and diffusion constant, g(r), Hall angle, maps),
:mod:`skygas.outputs` (movies, HTML reports, GSD and extended-XYZ exports). Everything else is
private and may change.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too). A Dask worker of a sweep
# imports only what a run needs this way, not xarray, zarr or the plotting code.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
