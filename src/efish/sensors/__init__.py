"""From raw field readings to what an agent perceives: noise, normalisation, encoding, ``sense``.

Sensor geometry (where the receptors sit) belongs to the physics
(:mod:`efish.physics.geometry`); this layer turns raw V/m readings into the
normalised values of docs/model/sensors.md#normalisation.
"""

from .normalize import binarize, knollen_size_channel, log_normalize

__all__ = ["binarize", "knollen_size_channel", "log_normalize"]
