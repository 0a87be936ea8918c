"""Paper panels from Parquet tables (docs/architecture.md#figures).

One module per figure (``fig2``, ``fig3``, ``supplement``), one function per
panel taking a dict of tables and a matplotlib Axes. :mod:`.registry` lists
every panel with the tables it reads, so the workflow builds one rule per panel
without repeating paths. Nothing here imports torch or the simulator.
"""
