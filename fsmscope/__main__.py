"""``python -m fsmscope ...`` is the ``fsmscope`` command."""

import sys

from fsmscope.server.cli import main

sys.exit(main())
