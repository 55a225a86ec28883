"""The Foxglove WebSocket protocol served live with foxglove-sdk: a Foxglove user connects to
``ws://127.0.0.1:PORT`` (through the door of ``foxglove_door.py``, which refuses the pages of
other sites) and sees, as they happen, the channels ``channels.py`` says (each
machine's events and active states, the transcript's lines, the arm's frames).

``event`` takes events in order per machine, from any thread; a machine joined mid-run starts
from a ``snapshot`` event (its status), as a new websocket of the dashboard does. A message is
encoded only when a Foxglove client subscribes to its channel (``has_sinks``)."""

from __future__ import annotations

import threading
from typing import Callable

import foxglove

from .channels import Channels, Frame, nanoseconds
from .foxglove_door import Admission, Door, inner_tls, quiet_inner_port


class FoxgloveLive:
    """A Foxglove WebSocket server on ``host``:``port`` (0: a free one, said by ``port``), open to
    whom ``admission`` admits; ``on_first_refusal`` is told why the first refused request was.
    Raises OSError when the port is taken."""

    def __init__(self, host: str = "127.0.0.1", port: int = 8765,
                 frames: Callable[[dict], list[Frame]] | None = None, admission: Admission = Admission(),
                 on_first_refusal: Callable[[str], None] = lambda reason: None) -> None:
        self.context = foxglove.Context()  # its own: never the process-wide default's sinks
        quiet_inner_port()
        cert, key = inner_tls()
        self.server = foxglove.start_server(name="fsmscope", host="127.0.0.1", port=0, context=self.context,
                                            tls_cert=cert, tls_key=key)
        try:
            self.door = Door(host, port, self.server.port, admission, on_first_refusal).start()
        except OSError:
            self.server.stop()
            raise
        self.port = self.door.port
        self.channels = Channels(frames)
        self._out: dict[str, foxglove.Channel] = {}
        self._lock = threading.Lock()  # the Statuses and the transcript follow one event at a time

    def event(self, event: dict) -> None:
        with self._lock:
            for m in self.channels.messages(event):
                channel = self._out.get(m.topic)
                if channel is None:
                    if m.schema is not None:
                        channel = foxglove.Channel(m.topic, schema=m.schema, context=self.context)
                    else:
                        known = type(m.data).get_schema()
                        channel = foxglove.Channel(m.topic, schema=known, message_encoding=known.encoding,
                                                   context=self.context)
                    self._out[m.topic] = channel
                if channel.has_sinks():
                    channel.log(m.data if m.schema is not None else m.data.encode(), log_time=nanoseconds(m.t))

    def watched(self) -> bool:
        """Whether a Foxglove client is connected (through the door)."""
        return self.door.visitors > 0

    def stop(self) -> None:
        self.door.stop()
        self.server.stop()
