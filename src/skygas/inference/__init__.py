"""From tracked skyrmions to a particle model (``skygas infer``; docs/inference.md).

:func:`infer` takes trackpy's tracks (a DataFrame or a file) and returns the diffusion constant,
the Hall angle and the forces the data show (a landscape, a pair law, a wall law, a drive),
inferred from the steps with their errors, the model material that every device reads with
``--material``, and the model's self-check; :func:`~skygas.inference.files.write_outputs`
writes them. :func:`~skygas.inference.synthetic.simulated_tracks` makes tracks of a known gas
with skygas's own engine.
"""

from skygas.inference.pipeline import Inference, infer

__all__ = ["Inference", "infer"]
