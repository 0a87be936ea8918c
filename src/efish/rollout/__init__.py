"""Policy + env -> Parquet tables with one declared schema (DESIGN "Tables")."""
