"""Receptor layouts, transduction and normalisation."""

from .layout import ampullary_angles, knollenorgan_angles, mormyromast_angles, sensor_frame
from .normalize import binarize, knollen_size_channel, log_normalize

__all__ = ["ampullary_angles", "binarize", "knollen_size_channel", "knollenorgan_angles",
           "log_normalize", "mormyromast_angles", "sensor_frame"]
