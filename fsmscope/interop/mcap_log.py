"""fsmscope's events in MCAP, the robotics world's log format, which Foxglove opens (docs/interop.md).

Written with the ``mcap`` library, on the channels ``channels.py`` says. Each message's log time is
its event's ``t``; its ``sequence`` is its place in the file, so the events read back in the order
they were written (not re-sorted by a wall clock). The file is written in chunks of CHUNK_BYTES: a
file cut short still yields every event before the chunk it was cut in.
"""

from __future__ import annotations

import json
import os
import struct
from typing import IO, Callable, Iterable, Iterator

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import Writer

from fsm.observation import schema
from fsm.observation.encoding import dumps, loads

from .channels import Channels, Frame, Message, nanoseconds
from .mcap_header import mcap_header
from .to_log import ReadError

LIBRARY = "fsmscope"  # the MCAP header's library: how ``is_fsmscope_mcap`` knows a file as ours
CHUNK_BYTES = 256 << 10  # a file cut short loses the chunk it was cut in: at most this much


class McapLogError(ReadError):
    """The file is no MCAP fsmscope wrote, or is damaged; the message says which."""


class _Out:
    """The writer and its channels, registered as they are first needed."""

    def __init__(self, stream: IO[bytes]) -> None:
        self.writer = Writer(stream, chunk_size=CHUNK_BYTES)
        self.writer.start(profile="", library=LIBRARY)
        self.schemas: dict[str, int] = {}
        self.channels: dict[str, int] = {}
        self.count = 0

    def schema(self, name: str, encoding: str, data: bytes) -> int:
        if name not in self.schemas:
            self.schemas[name] = self.writer.register_schema(name=name, encoding=encoding, data=data)
        return self.schemas[name]

    def channel(self, topic: str, encoding: str, schema_id: int) -> int:
        if topic not in self.channels:
            self.channels[topic] = self.writer.register_channel(topic=topic, message_encoding=encoding,
                                                                schema_id=schema_id)
        return self.channels[topic]

    def add(self, m: Message) -> None:
        channel = self.channels.get(m.topic)
        if channel is None:
            if m.schema is not None:
                encoding = MessageEncoding.JSON
                sid = self.schema(m.schema["title"], SchemaEncoding.JSONSchema, json.dumps(m.schema).encode())
            else:
                known = type(m.data).get_schema()
                encoding, sid = known.encoding, self.schema(known.name, known.encoding, bytes(known.data))
            channel = self.channel(m.topic, encoding, sid)
        self.writer.add_message(channel_id=channel, log_time=nanoseconds(m.t), publish_time=nanoseconds(m.t),
                                sequence=self.count,
                                data=dumps(m.data) if m.schema is not None else m.data.encode())
        self.count += 1


def write_mcap(events: Iterable[dict], out: str, frames: Callable[[dict], list[Frame]] | None = None) -> int:
    """The events (snapshots left out) into a new MCAP file ``out``; the number of events written.
    ``frames``: a pose event's frames (default: its free bodies', from the world)."""
    if os.path.exists(out):
        raise McapLogError("%s exists already" % out)
    channels = Channels(frames)
    partial = out + ".partial"
    written = 0
    try:
        with open(partial, "wb") as stream:
            o = _Out(stream)
            for event in events:
                if event["kind"] == "snapshot":  # no event of the run: the recorder's, for seeking
                    continue
                written += 1
                for m in channels.messages(event):
                    o.add(m)
            o.writer.finish()
    except BaseException:
        if os.path.exists(partial):
            os.remove(partial)
        raise
    os.replace(partial, out)
    return written


def is_fsmscope_mcap(path: str) -> bool:
    """Whether ``path`` is an MCAP file fsmscope wrote (its header's library)."""
    return getattr(mcap_header(path), "library", "").startswith(LIBRARY)


def read_mcap(path: str, on_problem: Callable[[str], None] | None = None) -> Iterator[dict]:
    """The events of an MCAP file ``write_mcap`` wrote, in the order written; a message that is no
    event of the schema is skipped (``on_problem`` hears why). A file cut short yields every event
    before the cut, then raises ``McapLogError``."""
    read = 0
    try:
        with open(path, "rb") as f:
            for _, channel, message in NonSeekingReader(f).iter_messages(log_time_order=False):
                if not (channel.topic.startswith("/fsmscope/") and channel.topic.endswith("/events")):
                    continue
                try:
                    event = loads(message.data)
                except ValueError as exc:
                    problem = "a message of %s that is no JSON (%s)" % (channel.topic, exc)
                else:
                    problem = schema.validate(event)
                if problem is None:
                    read += 1
                    yield event
                elif on_problem is not None:
                    on_problem(problem)
    except (McapError, struct.error, EOFError, ValueError) as exc:
        raise McapLogError("%s is damaged after %d events (%s: %s)" % (path, read, type(exc).__name__, exc)) from None
