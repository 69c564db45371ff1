"""skygas: stochastic Thiele simulation of magnetic skyrmion gases and skyrmionic devices.

Every public quantity is in SI units (metres, seconds, kelvin, newtons); sizes are diameters.

The names of :data:`__all__`, imported on first use:

- materials: :func:`preset`, :func:`preset_names`, :func:`load_material`, :class:`Material`,
  :func:`derive_thiele`, :class:`ThieleParameters`;
- geometry: :func:`disk`, :func:`rectangle`, :func:`polygon`, :func:`union`,
  :func:`chamber_with_conduits`, :class:`Outline`;
- the engine: :class:`Simulation` (``run``, ``add_random``, ``trajectories``, ``plot``);
- figures: :func:`plot` (recorded trajectories over the outline);
- configuration files: :func:`load_config`, :class:`SimulationConfig`, :func:`run_simulation`;
- errors: :class:`InputError`.

The public modules, also in :data:`__all__`:

- :mod:`skygas.engine` (the simulation, its operations and state),
  :mod:`skygas.physics` (materials, force laws, outlines),
  :mod:`skygas.fields` (the energy landscape :mod:`skygas.fields.landscape`, current flow, wall
  fields), :mod:`skygas.figures` (outlines, landscapes, trajectories and current flow drawn),
  :mod:`skygas.runs` (configurations, resumable runs, provenance);
- the devices: :mod:`skygas.reshuffler`, :mod:`skygas.neuron`, :mod:`skygas.reservoir`,
  :mod:`skygas.sc` (stochastic computing);
- studies and tools: :mod:`skygas.sweep` (parameter sweeps), :mod:`skygas.optimize` (design
  search), :mod:`skygas.analysis` (MSD and diffusion constants, g(r), Hall angle, maps),
  :mod:`skygas.outputs` (movies, HTML reports, exports), :mod:`skygas.micromag` (micromagnetic
  bridge), :mod:`skygas.calibration` (from film parameters to a particle model),
  :mod:`skygas.movies` (microscope movies: tracking and rendering) and :mod:`skygas.inference`
  (from an experiment's tracks to a particle model).

Names that begin with an underscore, :mod:`skygas.core` and :mod:`skygas.commands` are
internal and may change.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too). A Dask worker of a sweep
# imports only what a run needs this way, not xarray, zarr or the plotting code.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
