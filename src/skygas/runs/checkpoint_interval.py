"""The one wall-time interval between periodic checkpoints, shared by every command.

``skygas simulate``, ``demo``, ``reshuffle``, ``neuron``, ``saturation``, ``reservoir`` and
``calibrate`` save ``OUT/checkpoint.npz`` every :data:`CHECKPOINT_SECONDS` of wall time unless
``--checkpoint-seconds`` says otherwise (docs/runs.md). This module imports nothing, so the
command line can show the default without loading any numerics.
"""

#: Wall time [s] between periodic checkpoints: a kill loses at most this much work.
CHECKPOINT_SECONDS = 60.0
