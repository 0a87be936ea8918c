"""The world the agents live in: arenas, bodies, steps, tasks."""
