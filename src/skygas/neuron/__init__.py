"""The Skyrmion Neuron (paper, "Skyrmion Neuron"): a gated chamber of skyrmions.

The chamber integrates injected skyrmions, leaks them by annihilation, and fires by opening its
gate. See docs/neuron.md.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too), so that the command line and
# the modules of this package that need little import little.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
