"""Watching a machine: the event schema, the reporter that emits events (``attach``, global hooks),
the walks over a machine's structure (``structure``), the reducer that rebuilds a machine's state
from events (``Status``), and JSON encoding of values."""

from . import original  # noqa: F401  (registers the original SMACH's reporter with introspection.attach)
