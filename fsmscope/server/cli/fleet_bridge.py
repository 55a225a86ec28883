"""``serve --zenoh``: the dashboard shows the fleet's machines (the options, and the robot of ``run``
and ``demo --zenoh``, are fsmscope/server/cli/zenoh_options.py). A ``fleet.watcher.FleetWatcher``
follows every robot's machines on Zenoh; what it delivers goes through the hub's ingest door (each
event checked against the schema, as a publisher's are) on the server's event loop, and a machine
whose liveliness token is withdrawn is shown disconnected (``connected: false``) until it is back.
A machine whose robot takes controls gets a ``RemoteHandle`` (fsmscope/server/remote_control.py) whose link
is a ``FleetLink``: each control is a Zenoh query proving the robot's token (fsmscope/fleet/control.py), and
only batches and answers that prove it are shown (fsmscope/fleet/proofs.py)."""

from __future__ import annotations

import argparse
import sys
import threading
from typing import TYPE_CHECKING

from fsm.control.controls import Refused

from ..remote_control import RemoteHandle, not_connected, remote_controls, taken
from .cannot_serve import CannotServe
from .loop_inbox import LoopInbox, ingest_in_order
from .serving import SWITCH_INTERVAL
from .zenoh_options import reach, zenoh_tokens

if TYPE_CHECKING:
    from fsmscope.fleet.watcher import FleetWatcher

    from ..hub import Hub, MachineEntry


class FleetLink:
    """The link (fsmscope/server/remote_control.py) of one fleet machine's ``RemoteHandle``: its controls asked
    of its robot over Zenoh, with the dashboard's token for that robot."""

    def __init__(self, watcher: FleetWatcher, name: str, token: str, alive: dict[str, bool]) -> None:
        self.watcher = watcher
        self.name = name
        self.robot, _, self.machine = name.partition(":")
        self.token = token
        self._alive = alive

    @property
    def closed(self) -> bool:
        return not self._alive.get(self.name, False)

    @property
    def controllable(self) -> dict[str, bool]:
        offer = self.watcher.controls.get(self.name)
        return {self.name: offer["can_start"] is True} if offer else {}

    def ask(self, machine: str, action: str, params: dict, client: str) -> dict:
        """The robot's answer to a control (in a worker thread): as ``IngestLink.ask``."""
        if self.closed:
            raise not_connected(machine)
        answer = self.watcher.ask(self.robot, self.machine, self.token, action, params, client)
        if answer is None:
            # Zenoh ends a query its access control denies as if nobody were there, and a robot
            # answers no control that does not prove its token: say each.
            raise Refused(504, "no authenticated answer from robot %r to the control of %r: it is unreachable, "
                               "its Zenoh access control denies this dashboard's controls, or this dashboard's "
                               "token for it is not the robot's" % (self.robot, self.machine))
        return taken(machine, answer)

    def post(self, frame: dict) -> None:
        """A lease frame (any thread, never waits): the robot is told, naming this dashboard's session,
        so that it applies the deadman itself when this dashboard's beats stop (fsmscope/fleet/control.py)."""
        params = {key: frame[key] for key in ("held", "after", "action")}
        threading.Thread(target=self._tell, args=(params,), name="fsmscope-fleet-lease", daemon=True).start()

    def _tell(self, params: dict) -> None:
        answer = self.watcher.ask(self.robot, self.machine, self.token, "lease", params, "dashboard")
        if answer is None or answer.get("status") != 200:
            print("fsmscope serve: robot %r was not told of the lease on %r: %s" % (
                self.robot, self.machine, "no answer" if answer is None else answer.get("detail")),
                file=sys.stderr, flush=True)


def start_fleet(args: argparse.Namespace, hub: Hub) -> FleetWatcher:
    """The watcher, feeding ``hub`` on its loop until the process ends."""
    from fsmscope.fleet.watcher import FleetWatcher

    # The watcher's readers and the event loop take turns holding the GIL: at Python's default 5 ms
    # an event waited up to that long at each turn (bench/fleet_dashboard.py).
    sys.setswitchinterval(SWITCH_INTERVAL)
    inbox = LoopInbox(hub.loop)
    alive: dict[str, bool] = {}
    tokens = zenoh_tokens(args)

    def ingest(events: list[dict]) -> None:
        """One machine's events, in order."""
        entry = ingest_in_order(hub, events, "Zenoh")
        if entry is None:
            return
        entry.origin.connected = alive.get(entry.name, True)
        entry.origin.robot = entry.name.partition(":")[0]
        if not isinstance(entry.controls, RemoteHandle):
            bind(entry)

    def bind(entry: MachineEntry) -> None:
        """Its controls go to its robot when the robot takes them and this dashboard has its token."""
        robot = entry.name.partition(":")[0]
        token = tokens.get(robot, tokens.get(None))
        if token is not None and watcher.controls.get(entry.name):
            remote_controls(entry).bind(FleetLink(watcher, entry.name, token, alive))

    def seen(name: str, up: bool) -> None:
        alive[name] = up
        entry = hub.get(name)
        if entry is not None:
            entry.origin.connected = up
            controls = entry.controls
            if up and isinstance(controls, RemoteHandle) and controls.link is not None:
                controls.bind(controls.link)  # the lease said again: its process may be a new one

    try:
        watcher = FleetWatcher(lambda events: inbox.post(ingest, events), lambda name, up: inbox.post(seen, name, up),
                               connect=args.zenoh, listen=args.zenoh_listen, mode=args.zenoh_mode,
                               scouting=args.zenoh_scouting, config_file=args.zenoh_config, settled=inbox.wake,
                               tokens=tokens)
    except ValueError as exc:
        raise CannotServe(str(exc)) from None
    print("fsmscope: following the fleet on Zenoh (%s)" % reach(args.zenoh, args), file=sys.stderr, flush=True)
    return watcher
