"""Stochastic computing: bitstreams, correlation metrics, gates, circuits and decorrelators.

The skyrmion reshuffler exists to make stochastic-computing circuits work (paper, section
"Motivation: Stochastic Computing"). This subpackage provides the circuit side: stream
generators, the metrics that say how correlated two streams are, gates that compute on whole
streams, and the CMOS decorrelators the reshuffler is measured against. See
``docs/stochastic-computing.md``. The input signals of the devices (telegraph, Bernoulli or a
file, sampled at an injection clock) are :mod:`skygas.sc.signals`.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too), so that the command line and
# the modules of this package that need little import little.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
