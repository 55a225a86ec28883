"""Fleet tests' pieces: a free loopback tcp endpoint for Zenoh, a slow loop machine, and a TCP proxy
whose connections can be cut and let through again (a network drop between a robot and a dashboard)."""

from __future__ import annotations

import socket
import threading
import time

import fsm


def free_endpoint() -> str:
    """``tcp/127.0.0.1:PORT`` of a port free now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return "tcp/127.0.0.1:%d" % s.getsockname()[1]


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

    def close(self) -> None:
        self.cut()
        self.server.close()
