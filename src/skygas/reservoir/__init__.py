"""The Brownian reservoir.

Skyrmions in a confined chamber with contacts, whose thermally assisted, current-biased occupation
is read by magnetoresistive sensors and classified by a trained linear read-out (all 16 Boolean
functions of two inputs from one device, and temporal tasks). See docs/reservoir.md.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
