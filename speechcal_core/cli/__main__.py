"""Allow ``python -m speechcal_core.cli``."""

from __future__ import annotations

import sys

from speechcal_core.cli import main

sys.exit(main())
