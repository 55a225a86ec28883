"""The door of the live Foxglove server. Foxglove's protocol has no token, and foxglove-sdk's
server checks neither the Origin nor the Host of a handshake (``start_server`` has no hook for
either): a browser lets a page of any site, or a local file, open a websocket to 127.0.0.1, and a
site whose name is made to resolve to 127.0.0.1 (DNS rebinding) reaches it under its own name.

So the SDK's server listens on an inner port and the door on the public one: it reads each
request's head, refuses what ``Admission`` does not admit (HTTP 403; the first refusal is said,
the others only counted, so that nobody fills the terminal by knocking) and splices the rest,
byte for byte, to the inner port. The inner port speaks TLS only, with a certificate no browser
trusts (``inner_tls.pem``): a page that finds the inner port opens neither ``ws://`` nor
``wss://`` to it. That key is no secret and protects nothing by being one; programs of this
computer, which need no browser's help, can connect to either port, as they can read its files."""

from __future__ import annotations

import asyncio
import logging
import socket
import ssl
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

FOXGLOVE_WEB_APP = "https://app.foxglove.dev"
LOOPBACK_NAMES = frozenset({"127.0.0.1", "localhost", "::1"})
HEAD_LIMIT = 16 * 1024  # bytes of a handshake's request line and headers
HEAD_SECONDS = 10.0  # to send them
CHUNK = 64 * 1024
INNER_TLS = Path(__file__).with_name("inner_tls.pem")


@dataclass(frozen=True)
class Admission:
    """Who may open the door. A request without Origin comes from a program (a browser always
    sends one): admitted. A browser's must name an admitted origin: Foxglove's web app, or one the
    user allowed (``null`` is what a local file's page sends). Host must name the loopback, or a
    name the user allowed (DNS rebinding sends the attacker's)."""

    origins: frozenset[str] = frozenset({FOXGLOVE_WEB_APP})
    hosts: frozenset[str] = LOOPBACK_NAMES

    @classmethod
    def allowing(cls, origins: list[str] | None = None, hosts: list[str] | None = None) -> Admission:
        """The default admission, and ``origins`` and ``hosts`` besides (``--foxglove-origin``, ``--foxglove-host``)."""
        return cls(frozenset({FOXGLOVE_WEB_APP, *(_origin(o) for o in origins or ())}),
                   frozenset({*LOOPBACK_NAMES, *(_host_name(h) for h in hosts or ())}))

    def refusal(self, headers: list[tuple[str, str]]) -> str | None:
        """Why a request with ``headers`` (lower-case names) is refused; None when admitted."""
        hosts = [v for k, v in headers if k == "host"]
        origins = [v for k, v in headers if k == "origin"]
        if len(hosts) != 1 or _host_name(hosts[0]) not in self.hosts:
            return "Host %r is not this computer's loopback" % (hosts[0] if len(hosts) == 1 else hosts)
        if len(origins) > 1 or (origins and _origin(origins[0]) not in self.origins):
            return "a page of Origin %r may not connect" % (origins[0] if len(origins) == 1 else origins)
        return None


def _origin(value: str) -> str:
    return value.strip().rstrip("/").lower()


def _host_name(value: str) -> str:
    """A Host header's name without its port (an SSH tunnel may change the port), lower case."""
    value = value.strip().lower()
    if value.startswith("["):
        return value[1:value.find("]")] if "]" in value else value
    return value.rsplit(":", 1)[0].rstrip(".") if value.count(":") == 1 else value.rstrip(".")


def inner_tls() -> tuple[bytes, bytes]:
    """The inner port's certificate and key (PEM)."""
    text = INNER_TLS.read_bytes()
    start = text.index(b"-----BEGIN PRIVATE KEY-----")
    return text[:start], text[start:]


def quiet_inner_port() -> None:
    """The SDK logs an ERROR line for each client it drops; on the inner port any such client is a
    stranger (a page knocking with plain ``ws://``), whose knocks must not fill the terminal."""
    logging.getLogger("foxglove.websocket.server").setLevel(logging.CRITICAL + 1)


class Door:
    """The public port's listener, on ``host``:``port`` (0: a free one, said by ``port``), in its
    own thread and event loop; each admitted connection goes to ``inner_port`` over TLS.
    ``on_first_refusal`` is told why the first refused request was (``refused`` counts them)."""

    def __init__(self, host: str, port: int, inner_port: int, admission: Admission,
                 on_first_refusal: Callable[[str], None] = lambda reason: None) -> None:
        self.host, self.port, self.inner_port, self.admission = host, port, inner_port, admission
        self.on_first_refusal = on_first_refusal
        self.refused = 0
        self.visitors = 0  # connections admitted and open
        self._tls = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
        self._tls.check_hostname = False  # the inner port is ours, on the loopback: TLS is for browsers' sake
        self._tls.verify_mode = ssl.CERT_NONE
        self._thread: threading.Thread | None = None

    def start(self) -> Door:
        """Bind (raises OSError when the port is taken), then serve in a thread."""
        sock = socket.create_server((self.host, self.port))
        self.port = sock.getsockname()[1]
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="foxglove-door", daemon=True)
        self._thread.start()
        listening = asyncio.start_server(self._visit, sock=sock, limit=HEAD_LIMIT)
        self._server = asyncio.run_coroutine_threadsafe(listening, self._loop).result()
        return self

    def stop(self) -> None:
        def close() -> None:
            self._server.close()
            for task in asyncio.all_tasks(self._loop):
                task.cancel()
            self._loop.call_soon(self._loop.stop)

        if self._thread is not None:
            self._loop.call_soon_threadsafe(close)
            self._thread.join(5)
            self._thread = None
            self._loop.close()

    async def _visit(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            head = await asyncio.wait_for(reader.readuntil(b"\r\n\r\n"), HEAD_SECONDS)
            reason = self.admission.refusal(_headers(head))
            if reason is not None:
                self._refuse(writer, reason)
                return
            inner_reader, inner_writer = await asyncio.open_connection("127.0.0.1", self.inner_port, ssl=self._tls)
        except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, asyncio.TimeoutError, ValueError, OSError):
            writer.close()
            return
        inner_writer.write(head)
        both = [asyncio.ensure_future(_pipe(reader, inner_writer)), asyncio.ensure_future(_pipe(inner_reader, writer))]
        self.visitors += 1
        try:
            await asyncio.wait(both, return_when=asyncio.FIRST_COMPLETED)
        finally:
            self.visitors -= 1
            for task in both:
                task.cancel()
            writer.close()
            inner_writer.close()

    def _refuse(self, writer: asyncio.StreamWriter, reason: str) -> None:
        self.refused += 1
        if self.refused == 1:
            self.on_first_refusal(reason)
        body = reason.encode("utf-8", "replace")
        writer.write(b"HTTP/1.1 403 Forbidden\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: %d\r\n"
                     b"Connection: close\r\n\r\n%s" % (len(body), body))
        writer.close()


def _headers(head: bytes) -> list[tuple[str, str]]:
    lines = head.decode("latin-1").split("\r\n")[1:]
    pairs = [line.split(":", 1) for line in lines if ":" in line]
    return [(k.strip().lower(), v.strip()) for k, v in pairs]


async def _pipe(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    try:
        while chunk := await reader.read(CHUNK):
            writer.write(chunk)
            await writer.drain()
    except (OSError, ssl.SSLError):
        pass
