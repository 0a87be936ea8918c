"""``python -m efish``: the same command as ``efish``."""

import sys

from .cli import main

sys.exit(main())
