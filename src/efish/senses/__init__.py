"""The fish's senses: one registry (:data:`SENSES`) that every module names a sense through.

The three electroreceptor classes are written in several spellings across the tables and configs (the config
group ``sensors.mormyromast``, the measure column ``err_morm_rad``, the letter ``M`` in the ablation conditions'
names ``M_A_K``, the label "Mormyromast" on a figure); each spelling is a field of one :class:`Sense`, so code
derives it instead of writing it out. Nothing here imports from the rest of efish.
"""

from .registry import SENSES, Sense, condition_name, error_column, sense

__all__ = ["SENSES", "Sense", "condition_name", "error_column", "sense"]
