"""Tasks: placement at reset, rewards and termination, one module each (``foraging``, ``homing``).

``env.task`` names the task; :func:`make_task` builds it. The engine calls a
task only through the contract of :class:`~efish.env.tasks.base.Task`.
"""

from __future__ import annotations

from ...config.schema import EfishConfig
from .base import StepEvents, Task
from .foraging import Foraging
from .homing import Homing

TASKS: dict[str, type[Task]] = {"foraging": Foraging, "homing": Homing}


def make_task(cfg: EfishConfig, n_agents: int | None = None) -> Task:
    """The task ``cfg.env.task`` for ``n_agents`` agents (default ``cfg.env.n_agents``)."""
    try:
        cls = TASKS[cfg.env.task]
    except KeyError:
        raise ValueError(f"unknown task {cfg.env.task!r}: choose one of {', '.join(TASKS)}") from None
    return cls(cfg, cfg.env.n_agents if n_agents is None else n_agents)


__all__ = ["TASKS", "Foraging", "Homing", "StepEvents", "Task", "make_task"]
