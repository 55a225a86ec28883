"""Fleet tests' pieces: a free loopback tcp endpoint for Zenoh, a slow loop machine, a TCP proxy
whose connections can be cut and let through again (a network drop between a robot and a dashboard),
and real processes: a dashboard (``fsmscope serve --zenoh``), robots (``fsmscope run
robots/patrol.py --zenoh ROBOT``) and routers (``fsmscope router``)."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import fsm
import httpx

from fsmscope.fleet.watcher import FleetWatcher
from fsm.logfiles.log_reader import read_events
from fsm.observation.status import Status
from fsmscope.server.testing.demo_process import free_endpoint
from fsmscope.server.testing.polling import wait_for

ROOT = Path(__file__).resolve().parents[1]
PATROL = Path(__file__).resolve().parent / "robots" / "patrol.py"

TOKEN = "the-fleets-token"  # what the tests' robots prove, and their dashboards hold



class Tick(fsm.State):
    """Waits ``pause`` seconds, then goes on, until the loop has ticked ``steps`` times or is preempted."""

    def __init__(self, count: list[int], steps: int, pause: float) -> None:
        fsm.State.__init__(self, ["go", "stop"], output_keys=["ticks"])
        self.count, self.steps, self.pause = count, steps, pause

    def execute(self, ud):
        time.sleep(self.pause)
        self.count[0] += 1
        ud.ticks = self.count[0]
        if self.preempt_requested():
            self.service_preempt()
            return "stop"
        return "stop" if self.count[0] >= self.steps else "go"


def slow_loop(steps: int, pause: float = 0.01) -> fsm.StateMachine:
    """A -> B -> A ... ``steps`` ticks of ``pause`` seconds (or until preempted), then done; its userdata
    counts the ticks."""
    count = [0]
    sm = fsm.StateMachine(["done"])
    sm.userdata.ticks = 0
    with sm:
        fsm.StateMachine.add("A", Tick(count, steps, pause), {"go": "B", "stop": "done"})
        fsm.StateMachine.add("B", Tick(count, steps, pause), {"go": "A", "stop": "done"})
    return sm


def run_published(robot, sm: fsm.StateMachine, name: str = "loop") -> tuple[list[dict], threading.Thread]:
    """``sm`` published by ``robot`` as ``name``, run in a thread: the events of the robot's own stream
    (what its log has), and the thread."""
    own: list[dict] = []
    fsm.attach(sm, robot, name=name)
    fsm.attach(sm, own.append)
    runner = threading.Thread(target=sm.execute, daemon=True)
    runner.start()
    return own, runner


class Proxy:
    """Forwards ``tcp/127.0.0.1:<port>`` (its ``endpoint``) to ``target`` until ``cut()``, which closes
    every connection and refuses new ones until ``restore()``."""

    def __init__(self, target: str) -> None:
        self.target = ("127.0.0.1", int(target.rsplit(":", 1)[1]))
        self.server = socket.socket()
        self.server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.server.bind(("127.0.0.1", 0))
        self.server.listen()
        self.endpoint = "tcp/127.0.0.1:%d" % self.server.getsockname()[1]
        self.open = True
        self.sockets: list[socket.socket] = []
        self.lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                client, _ = self.server.accept()
            except OSError:
                return
            if not self.open:
                client.close()
                continue
            upstream = socket.create_connection(self.target)
            with self.lock:
                self.sockets += [client, upstream]
            for a, b in ((client, upstream), (upstream, client)):
                threading.Thread(target=self._pipe, args=(a, b), daemon=True).start()

    @staticmethod
    def _pipe(a: socket.socket, b: socket.socket) -> None:
        try:
            while data := a.recv(65536):
                b.sendall(data)
        except OSError:
            pass
        for s in (a, b):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    def cut(self) -> None:
        self.open = False
        with self.lock:
            sockets, self.sockets = self.sockets, []
        for s in sockets:
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            s.close()

    def restore(self) -> None:
        self.open = True

    def point_to(self, target: str) -> None:
        """Connections from now on go to ``target`` (a dashboard that replaced another)."""
        self.target = ("127.0.0.1", int(target.rsplit(":", 1)[1]))

    def close(self) -> None:
        self.cut()
        self.server.close()


def started(command: list[str], said: str) -> tuple[subprocess.Popen, re.Match]:
    """``fsmscope COMMAND`` in a real process of its own group, once its stderr has said ``said`` (a
    pattern): the process and the match. Its stderr is read on after, so it never blocks on a full pipe."""
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", *command], cwd=ROOT, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    for line in proc.stderr:
        found = re.search(said, line)
        if found:
            threading.Thread(target=proc.stderr.read, daemon=True).start()
            return proc, found
    raise RuntimeError("fsmscope %s ended before it said %r" % (command[0], said))


def stop(proc: subprocess.Popen) -> None:
    """SIGTERM to its group (a SIGINT is ignored by a process started in the background), and wait."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
    proc.wait(20)


class Dashboard:
    """``fsmscope serve --zenoh`` in a real process, listening on a Zenoh endpoint of its own
    (``listen``), or only connecting where its options say (a router's client)."""

    def __init__(self, *options: str, listen: bool = True) -> None:
        self.endpoint = free_endpoint() if listen else None
        own = ["--zenoh-listen", self.endpoint] if listen else []
        self.proc, found = started(["serve", "--port", "0", "--zenoh", *own, *options],
                                   r"serving the dashboard at (http://\S+)")
        self.base, self.token = found.group(1).split("/?token=")

    def machines(self) -> dict[str, dict]:
        return {m["name"]: m for m in httpx.get(self.base + "/api/machines", params={"token": self.token}).json()}

    def post(self, path: str, body: dict) -> httpx.Response:
        return httpx.post(self.base + path, params={"token": self.token}, json=body, timeout=10)

    def stop(self) -> None:
        stop(self.proc)


class Router:
    """``fsmscope router`` in a real process, listening on ``endpoint`` (None: a free one); ``options``:
    its others (``--connect`` another site's router)."""

    def __init__(self, *options: str, endpoint: str | None = None) -> None:
        self.endpoint = endpoint or free_endpoint()
        self.proc, _ = started(["router", "--listen", self.endpoint, *options], r"routing Zenoh on")

    def stop(self) -> None:
        stop(self.proc)


class Robot:
    """Robot ``name`` in a real process: ``fsmscope run robots/patrol.py --no-serve --zenoh NAME``,
    connecting to ``endpoint`` and recording to ``log``; ``fail``: its patrol fails on the third scan;
    ``options``: more of ``run``'s (``--zenoh-mode client``, behind a router). Restarted
    (``start`` again), it appends to its log, as a robot's service would (``--append``)."""

    def __init__(self, name: str, endpoint: str, token: str, log: Path, fail: bool = False,
                 options: tuple[str, ...] = ()) -> None:
        self.name, self.endpoint, self.token, self.log, self.fail = name, endpoint, token, log, fail
        self.options = options
        self.proc: subprocess.Popen | None = None
        self.start()

    def start(self) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "fsmscope", "run", str(PATROL), "--no-serve", "--record", str(self.log), "--append",
             "--zenoh", self.name, "--zenoh-connect", self.endpoint, "--zenoh-token", self.token, *self.options,
             *(["--", "fail"] if self.fail else [])],
            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)

    def kill(self) -> None:
        """Gone at once, as a robot that loses power: nothing is closed or said."""
        os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait(10)

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.kill()

    def events(self) -> list[dict]:
        """What the robot recorded in its own log."""
        return list(read_events(str(self.log)))

    def ended(self, timeout: float = 15) -> int:
        """Wait for its script to end; its exit code."""
        wait_for(lambda: self.proc.poll() is not None, timeout, what="robot %s's script to end" % self.name)
        return self.proc.returncode


def history(dash: Dashboard, name: str, since: int) -> list[dict]:
    """The dashboard's events of machine ``name`` from seq ``since`` on."""
    events: list[dict] = []
    while since is not None:
        page = httpx.get(dash.base + "/api/machines/%s/history" % name,
                         params={"token": dash.token, "since": since, "limit": 1000}).json()
        events += page["events"]
        since = page["next"] if page["more"] else None
    return events


def preempted_the_dashboard_has_the_robots_log(dash: Dashboard, robot: Robot, since: int) -> None:
    """Preempt r1:patrol from ``dash``: its run ends, and the dashboard's events from ``since`` on are
    those of the robot's own log."""
    answer = dash.post("/api/machines/r1:patrol/preempt", {})
    assert answer.status_code == 202, answer.text
    assert robot.ended() == 0
    own = [e for e in robot.events() if e["seq"] >= since]
    wait_for(lambda: dash.machines()["r1:patrol"]["last_seq"] == own[-1]["seq"], 10, what="the last event")
    seen = history(dash, "r1:patrol", since)
    shown, logged = [(e["seq"], e["kind"]) for e in seen], [(e["seq"], e["kind"]) for e in own]
    assert shown == logged, "missing %r, extra %r" % (sorted(set(logged) - set(shown)), sorted(set(shown) - set(logged)))


class Delivered:
    """What a watcher delivered: the events, in order, and each machine's comings and goings."""

    def __init__(self, **session) -> None:
        self.events: list[dict] = []
        self.alive: list[tuple[str, bool]] = []
        self.watcher = FleetWatcher(self.events.extend, lambda name, up: self.alive.append((name, up)),
                                   tokens={None: TOKEN}, **session)

    def status(self, name: str) -> Status:
        """The machine's state rebuilt from what was delivered: from its last snapshot (or its first
        event), the events."""
        events = [event for event in self.events if event["machine"] == name]
        start = max([i for i, event in enumerate(events) if event["kind"] == "snapshot"], default=0)
        status = Status(name)
        for event in events[start:]:
            status.apply(event)
        return status


EVERY_MESSAGE = ["put", "delete", "declare_subscriber", "query", "declare_queryable", "reply", "liveliness_token",
                 "declare_liveliness_subscriber", "liveliness_query"]  # zenoh-config's AclMessage, all of them


def access_configuration(directory: Path, name: str, passwords: dict[str, str], access_control: dict) -> str:
    """A Zenoh configuration file (``name``.json5 in ``directory``) that checks each session's user
    and password against ``passwords`` (its dictionary file beside it) and applies ``access_control``."""
    users = directory / (name + "-users.txt")
    users.write_text("".join("%s:%s\n" % item for item in passwords.items()))
    path = directory / (name + ".json5")
    path.write_text(json.dumps({"transport": {"auth": {"usrpwd": {"dictionary_file": str(users)}}},
                                "access_control": access_control}, indent=2))
    return str(path)


def user_configuration(directory: Path, user: str, password: str) -> str:
    """A Zenoh configuration file that opens a session as ``user`` with ``password``."""
    path = directory / ("user-%s-%s.json5" % (user, password))
    path.write_text(json.dumps({"transport": {"auth": {"usrpwd": {"user": user, "password": password}}}}))
    return str(path)
