"""Recurrent MAPPO: networks, action distribution, advantages, value normalisation."""
