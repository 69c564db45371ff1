"""Names of :mod:`skygas.neuron`, imported on first use (see ``__init__.py``)."""

from .analysis import isi_statistics, leak_from_log, measure_leak, transfer_curve
from .annihilation import AnnihilationModel, Annihilator
from .calibration import CALIBRATED
from .config import NeuronConfig, load_neuron_config, neuron_config
from .device import NeuronDevice, NeuronRun, run_neuron
from .inputs import InputSpec
from .lif import fit_lif, lif_rate
from .saturation import close_packing_estimate, saturation_curve, saturation_estimate

__all__ = [
    "AnnihilationModel",
    "Annihilator",
    "CALIBRATED",
    "InputSpec",
    "NeuronConfig",
    "NeuronDevice",
    "NeuronRun",
    "close_packing_estimate",
    "fit_lif",
    "isi_statistics",
    "leak_from_log",
    "lif_rate",
    "load_neuron_config",
    "measure_leak",
    "neuron_config",
    "run_neuron",
    "saturation_curve",
    "saturation_estimate",
    "transfer_curve",
]
