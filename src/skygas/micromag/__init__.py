"""The micromagnetics bridge: from OOMMF/mumax3 magnetisation files to the particle model.

Read OVF snapshots (:func:`read_ovf`), measure the topological charge Q and the dissipation 𝒟
(:func:`topological_charge`, :func:`dissipation`), find skyrmions (:func:`detect_skyrmions`),
link them into trajectories (:func:`link`), turn their motion into forces F = Ĝ^α·ẋ and fit the
paper's pair and wall laws (:func:`fit_trajectories`, :func:`fit_snapshots`), and export the
result as a material preset that :func:`skygas.physics.materials.load_material` reads.
See ``docs/micromagnetics.md``.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too), so that the command line and
# the modules of this package that need little import little.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
