"""From tracked skyrmions to a particle model (``skygas infer``; docs/inference.md).

:func:`infer` takes trackpy's tracks (a DataFrame or a file) and returns the diffusion constant,
the Hall angle, the pinning landscape, the wall and pair laws and the model material that every
device reads with ``--material``; :func:`~skygas.inference.files.write_outputs` writes them.
:func:`~skygas.inference.synthetic.simulated_tracks` makes tracks of a known gas for checks.
"""

from skygas.inference.pipeline import Inference, infer

__all__ = ["Inference", "infer"]
