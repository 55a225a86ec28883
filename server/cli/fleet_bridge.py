"""``--zenoh`` of the commands: ``run`` and ``demo`` publish their machines as a robot's
(``fleet.robot.ZenohRobot``); ``serve`` shows the fleet's machines in the dashboard. A ``fleet.watcher.FleetWatcher``
follows every robot's machines on Zenoh; what it delivers goes through the hub's ingest door (each
event checked against the schema, as a publisher's are) on the server's event loop, and a machine
whose liveliness token is withdrawn is shown disconnected (``connected: false``) until it is back.
A machine whose robot takes controls gets a ``RemoteHandle`` (server/remote_control.py) whose link
is a ``FleetLink``: each control is a Zenoh query carrying the robot's token (fleet/control.py)."""

from __future__ import annotations

import argparse
import asyncio
import collections
import os
import secrets
import sys
import threading
from typing import TYPE_CHECKING, Callable

from fsm.control.controls import Refused

from ..remote_control import RemoteHandle, not_connected, remote_controls, taken
from .cannot_serve import CannotServe
from .serving import SWITCH_INTERVAL

if TYPE_CHECKING:
    from fleet.robot import ZenohRobot
    from fleet.watcher import FleetWatcher

    from ..hub import Hub, MachineEntry


def add_zenoh_arguments(parser: argparse.ArgumentParser, publish: bool) -> None:
    """``publish`` (run, demo): ``--zenoh ROBOT`` puts the machines on Zenoh as that robot's; else
    (serve): ``--zenoh [ENDPOINT ...]`` follows the fleet."""
    if publish:
        parser.add_argument("--zenoh", metavar="ROBOT",
                            help="also publish the machines on Zenoh as this robot's (docs/fleet.md)")
        parser.add_argument("--zenoh-connect", action="append", default=[], metavar="ENDPOINT",
                            help="with --zenoh: connect to this endpoint (tcp/HOST:PORT: a dashboard's or a router's)")
    else:
        parser.add_argument("--zenoh", nargs="*", metavar="ENDPOINT",
                            help="follow the fleet's machines on Zenoh, connecting to these endpoints (tcp/HOST:PORT: "
                                 "a robot's, or a zenohd router's); none: only --zenoh-listen and --zenoh-scouting")
    parser.add_argument("--zenoh-listen", action="append", default=[], metavar="ENDPOINT",
                        help="with --zenoh: also listen on this endpoint, for sessions that connect here")
    parser.add_argument("--zenoh-token", action="append", default=[], metavar="[ROBOT=]TOKEN",
                        help=("with --zenoh: the token the robot's controls must carry (default: $%s; none: a new "
                              "one, printed)" % TOKEN_ENV) if publish else
                             ("with --zenoh: the token to control the robots' machines with; ROBOT=TOKEN for one "
                              "robot's (default: $%s; none: the fleet is watched, not controlled)" % TOKEN_ENV))
    parser.add_argument("--zenoh-mode", choices=("peer", "client"), default="peer",
                        help="with --zenoh: peer (default; a robot connecting to a router stays one), or client of "
                             "a router (a dashboard behind one)")
    parser.add_argument("--zenoh-scouting", action="store_true",
                        help="with --zenoh: find the others on the LAN by multicast (off unless asked)")
    parser.add_argument("--zenoh-config", type=zenoh_config_file, metavar="FILE",
                        help="with --zenoh: a Zenoh configuration file (JSON5) for the rest, such as TLS "
                             "certificates for tls/ endpoints; the options above are applied over it")


def zenoh_config_file(path: str) -> str:
    """``--zenoh-config``'s check: a file Zenoh reads as its configuration (else the command says why)."""
    from fleet.config import read_config_file

    try:
        read_config_file(path)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


TOKEN_ENV = "FSMSCOPE_ZENOH_TOKEN"
ZENOH_OPTIONS = ("zenoh_connect", "zenoh_listen", "zenoh_token", "zenoh_mode", "zenoh_scouting", "zenoh_config")


def zenoh_tokens(args: argparse.Namespace) -> dict[str | None, str]:
    """The tokens of ``--zenoh-token`` by robot (None: any robot's), with $FSMSCOPE_ZENOH_TOKEN for any."""
    tokens: dict[str | None, str] = {}
    if os.environ.get(TOKEN_ENV):
        tokens[None] = os.environ[TOKEN_ENV]
    for value in args.zenoh_token:
        robot, _, token = value.rpartition("=")
        tokens[robot or None] = token
    return tokens


def zenoh_robot(args: argparse.Namespace, can_start: bool) -> ZenohRobot | None:
    """With ``--zenoh ROBOT``: the observer that publishes machines as that robot's, taking the
    controls that carry its token; else None."""
    if args.zenoh is None:
        return None
    from fleet.robot import ZenohRobot

    given = zenoh_tokens(args).get(None)
    token = given or secrets.token_urlsafe(24)
    try:
        robot = ZenohRobot(args.zenoh, connect=args.zenoh_connect, listen=args.zenoh_listen, mode=args.zenoh_mode,
                           scouting=args.zenoh_scouting, token=token, can_start=can_start,
                           config_file=args.zenoh_config)
    except ValueError as exc:  # a name Zenoh cannot take, an endpoint it cannot use
        raise CannotServe(str(exc)) from None
    if given is None:
        print("fsmscope: the token of robot %r's controls: %s (serve --zenoh-token %s=%s)"
              % (args.zenoh, token, args.zenoh, token), file=sys.stderr, flush=True)
    print("fsmscope: publishing on Zenoh as robot %r (%s)" % (args.zenoh, reach(args.zenoh_connect, args)),
          file=sys.stderr, flush=True)
    return robot


def robot_follows(robot: ZenohRobot, entry: MachineEntry) -> None:
    """A machine this process's dashboard serves too: the robot publishes the events the hub encodes
    anyway (a sink of its feed, rather than observing the machine itself), applies the dashboards'
    controls through the hub's handle, and answers state queries from the hub's Status."""
    feed = entry.feed
    feed.add_encoded_sink(robot.follow(entry.name, entry.local.handle, feed.lock, lambda: feed.status))


class FleetLink:
    """The link (server/remote_control.py) of one fleet machine's ``RemoteHandle``: its controls asked
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
            # Zenoh ends a query its access control denies as if nobody were there: say both.
            raise Refused(504, "robot %r did not answer the control of %r: it is unreachable, or its Zenoh "
                                    "access control denies this dashboard's controls" % (self.robot, self.machine))
        return taken(machine, answer)

    def post(self, frame: dict) -> None:
        """A lease frame (any thread, never waits): the robot is told, naming this dashboard's session,
        so that it applies the deadman itself when this dashboard is gone (fleet/control.py)."""
        params = {key: frame[key] for key in ("held", "after", "action")}
        params["dashboard"] = self.watcher.id
        threading.Thread(target=self._tell, args=(params,), name="fsmscope-fleet-lease", daemon=True).start()

    def _tell(self, params: dict) -> None:
        answer = self.watcher.ask(self.robot, self.machine, self.token, "lease", params, "dashboard")
        if answer is None or answer.get("status") != 200:
            print("fsmscope serve: robot %r was not told of the lease on %r: %s" % (
                self.robot, self.machine, "no answer" if answer is None else answer.get("detail")),
                file=sys.stderr, flush=True)


class LoopInbox:
    """What the watcher's threads hand to the event loop, in order: calls queued, run together when the
    watcher says the samples that came together are handled (``wake``). A fleet's robots put on the
    same tick, so its thousands of batches a second wake the loop a few hundred times, not once per
    batch: each wake costs the loop more than ingesting an event does."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self._calls: collections.deque[tuple[Callable[..., None], tuple]] = collections.deque()
        self._lock = threading.Lock()
        self._scheduled = False

    def post(self, call: Callable[..., None], *args: object) -> None:
        """From any thread: ``call(*args)`` on the loop, after those posted before it, at the next ``wake``."""
        self._calls.append((call, args))

    def wake(self) -> None:
        """From any thread: run what was posted, unless the loop is about to."""
        with self._lock:
            if self._scheduled or not self._calls:
                return
            self._scheduled = True
        self.loop.call_soon_threadsafe(self._run)

    def _run(self) -> None:
        with self._lock:
            self._scheduled = False
        calls = self._calls
        for _ in range(len(calls)):  # those posted meanwhile come with a wake of their own
            call, args = calls.popleft()
            call(*args)


def start_fleet(args: argparse.Namespace, hub: Hub) -> FleetWatcher:
    """The watcher, feeding ``hub`` on its loop until the process ends."""
    from fleet.watcher import FleetWatcher

    # The watcher's readers and the event loop take turns holding the GIL: at Python's default 5 ms
    # an event waited up to that long at each turn (bench/fleet_dashboard.py).
    sys.setswitchinterval(SWITCH_INTERVAL)
    inbox = LoopInbox(hub.loop)
    alive: dict[str, bool] = {}
    tokens = zenoh_tokens(args)

    def ingest(events: list[dict]) -> None:
        """One machine's events, in order."""
        for event in events:
            problem = hub.ingest(event, "ingest")
            if problem:
                print("fsmscope serve: refused an event of %s from Zenoh: %s" % (event.get("machine"), problem),
                      file=sys.stderr, flush=True)
        entry = hub.get(events[0]["machine"])
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
                               scouting=args.zenoh_scouting, config_file=args.zenoh_config, settled=inbox.wake)
    except ValueError as exc:
        raise CannotServe(str(exc)) from None
    print("fsmscope: following the fleet on Zenoh (%s)" % reach(args.zenoh, args), file=sys.stderr, flush=True)
    return watcher


def reach(connect: list[str], args: argparse.Namespace) -> str:
    """Where the command's Zenoh session meets the others, for the line it starts with: a session
    given no endpoint, no scouting and no configuration file meets nobody, and says so."""
    parts = (["connect " + e for e in connect] + ["listen " + e for e in args.zenoh_listen]
             + (["multicast scouting"] if args.zenoh_scouting else [])
             + (["configured by " + args.zenoh_config] if args.zenoh_config else []))
    return ", ".join(parts) or "no endpoint and no scouting: it meets nobody"
