"""The ``efish`` command's own logic: the training log line."""

from __future__ import annotations

import math

from efish.cli import ReturnLog


def test_the_training_log_never_prints_nan():
    log = ReturnLog()
    assert log.line({"episode_return": math.nan, "episodes_ended": 0}) == "no episode ended yet"
    assert log.line({"episode_return": 12.5, "episodes_ended": 3}) == "return 12.500 (3 episodes)"
    assert log.line({"episode_return": math.nan, "episodes_ended": 0}) == "no episode ended since the last line"
    assert "nan" not in log.line({"episode_return": -1.0, "episodes_ended": 1})
