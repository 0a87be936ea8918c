"""The paper's claims as verdicts (docs/claims/index.md), read from a run's analysis tables.

The files show the structure: :mod:`.verdicts` (the rules), :mod:`.statistics`
(the tests and intervals no analysis table holds), :mod:`.context` (what a
claim is), :mod:`.parts` (the tests claims share), one module per figure
(:mod:`.fig2` .. :mod:`.fig6`), :mod:`.registry` (the list of claims),
:mod:`.table` (a run's claims table); and for reading them: :mod:`.seeds`
(each top seed's verdict), :mod:`.recipe` (the recipe's verdict over the seeds), :mod:`.stages` (along training),
:mod:`.report` (markdown, two runs side by side).
"""

from .registry import CLAIMS, claim_tables, produced_tables
from .table import claims_and_parts, claims_table
from .verdicts import PART_COLUMNS, ROW_COLUMNS, VERDICTS

__all__ = ["CLAIMS", "PART_COLUMNS", "ROW_COLUMNS", "VERDICTS", "claim_tables", "claims_and_parts", "claims_table",
           "produced_tables"]
