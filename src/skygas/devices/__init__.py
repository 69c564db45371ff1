"""The device registry: what every kind of run is, in one place.

:mod:`skygas.devices.registry` holds one :class:`~skygas.devices.registry.DeviceKind` per
command that runs a device or a plain simulation; the code serving every kind (the report,
``skygas check-timestep``, the analysis) asks it instead of switching on a kind's name.
:mod:`skygas.devices.timestep` holds the parts of the time-step check the kinds share.
"""
