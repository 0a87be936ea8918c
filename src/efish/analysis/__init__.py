"""Pure functions on rollout tables; no torch, no simulator (docs/architecture.md)."""
