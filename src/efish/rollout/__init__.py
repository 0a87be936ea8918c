"""Policy + env -> Parquet tables with one declared schema (docs/architecture.md#tables)."""
