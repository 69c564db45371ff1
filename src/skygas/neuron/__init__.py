"""The Skyrmion Neuron (paper, "Skyrmion Neuron"): a gated chamber that integrates injected
skyrmions, leaks them by annihilation, and fires by opening its gate. See docs/neuron.md."""

from skygas.neuron.analysis import isi_statistics, leak_from_log, measure_leak, transfer_curve
from skygas.neuron.lif import fit_lif, lif_rate
from skygas.neuron.annihilation import AnnihilationModel, Annihilator
from skygas.neuron.calibration import CALIBRATED
from skygas.neuron.config import NeuronConfig, load_neuron_config, neuron_config
from skygas.neuron.device import NeuronDevice, NeuronRun, run_neuron
from skygas.neuron.inputs import InputSpec
from skygas.neuron.saturation import (close_packing_estimate, saturation_curve,
                                      saturation_estimate)

__all__ = ["AnnihilationModel", "Annihilator", "CALIBRATED", "InputSpec", "NeuronConfig",
           "NeuronDevice", "NeuronRun", "close_packing_estimate", "fit_lif", "isi_statistics",
           "leak_from_log", "lif_rate", "load_neuron_config", "measure_leak", "neuron_config",
           "run_neuron", "saturation_curve", "saturation_estimate", "transfer_curve"]
