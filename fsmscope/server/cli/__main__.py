"""``python -m fsmscope.server.cli ...``: the ``fsmscope`` command (``python -m fsmscope`` too)."""

import sys

from . import main

sys.exit(main())
