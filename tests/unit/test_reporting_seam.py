"""fsm.core reports through its own seam (fsm/core/reporting.py); fsm.observation's Reporter implements it."""

from __future__ import annotations

import inspect

from fsm.core import reporting
from fsm.observation import introspection


def _calls(cls: type) -> dict[str, list[str]]:
    return {name: list(inspect.signature(member).parameters)
            for name, member in vars(cls).items() if callable(member) and not name.startswith("_")}


def test_the_observation_reporter_takes_every_call_core_makes_with_the_same_parameters():
    implemented = _calls(introspection.Reporter)
    assert {name: implemented.get(name) for name in _calls(reporting.Reporter)} == _calls(reporting.Reporter)


def test_the_global_hooks_users_import_from_fsm_are_the_seams_own():
    import fsm

    assert fsm.add_global_hook is reporting.add_global_hook and fsm.remove_global_hook is reporting.remove_global_hook
