"""``python -m server.cli ...``: the ``fsmscope`` command (the tests run it so)."""

import sys

from . import main

sys.exit(main())
