"""``--foxglove PORT``: the served machines on the Foxglove WebSocket protocol too
(fsmscope/interop/foxglove_live.py), fed from the hub as a dashboard's websocket is: each machine's events
from its feed's ring, on the server's event loop (where the ring changes), and its snapshot when it
joins or falls further behind than the ring keeps; only while a Foxglove client is connected (a
server nobody looks at costs the machines nothing). A command that serves no dashboard (``run
--no-serve``, ``demo --headless``) has no hub: it gives the server its machines' events by
observing them (``fsm.attach(machine, live.event)``), in their threads."""

from __future__ import annotations

import argparse
import asyncio
import sys
from typing import TYPE_CHECKING

from fsm.observation.encoding import loads

from .cannot_serve import CannotServe

if TYPE_CHECKING:
    from fsmscope.interop.foxglove_live import FoxgloveLive

    from ..hub import Hub

LOOPBACK = "127.0.0.1"
POLL_SECONDS = 0.05
BATCH = 2000  # events of one machine taken per poll at most


def open_foxglove(args: argparse.Namespace) -> FoxgloveLive:
    """The Foxglove server on 127.0.0.1 and ``--foxglove``, said on stderr with who may connect.
    Foxglove's protocol has no token: it is never served on another address than the loopback,
    whatever ``--host`` says (reach it from elsewhere through an SSH tunnel), and its door refuses
    web pages but Foxglove's and those of ``--foxglove-origin``, and Host names but the loopback's
    and those of ``--foxglove-host`` (fsmscope/interop/foxglove_door.py). Raises CannotServe."""
    from fsmscope.interop.foxglove_door import FOXGLOVE_WEB_APP, LOOPBACK_NAMES, Admission
    from fsmscope.interop.foxglove_live import FoxgloveLive

    from .arm_frames import arm_frames

    admission = Admission.allowing(args.foxglove_origin, args.foxglove_host)
    try:
        live = FoxgloveLive(LOOPBACK, args.foxglove, frames=arm_frames(), admission=admission,
                            on_first_refusal=_say_refused)
    except (RuntimeError, OSError) as exc:  # foxglove-sdk's or the door's: the port is taken
        raise CannotServe("the Foxglove server cannot start: %s" % exc) from exc
    origins = [FOXGLOVE_WEB_APP, *sorted(admission.origins - {FOXGLOVE_WEB_APP})]
    hosts = sorted(admission.hosts - LOOPBACK_NAMES)
    print("fsmscope: Foxglove WebSocket at ws://%s:%d (no token: programs of this computer and web pages of %s "
          "may connect; other pages are refused%s)" % (LOOPBACK, live.port, ", ".join(origins),
                                                        "; also named %s" % ", ".join(hosts) if hosts else ""),
          file=sys.stderr, flush=True)
    return live


def _say_refused(reason: str) -> None:
    print("fsmscope: a Foxglove connection was refused: %s (--foxglove-origin, --foxglove-host allow more); "
          "further refusals are not said" % reason, file=sys.stderr, flush=True)


def start_foxglove(args: argparse.Namespace, hub: Hub) -> FoxgloveLive:
    """The Foxglove server on ``--foxglove``, fed from ``hub`` until the process ends."""
    live = open_foxglove(args)
    asyncio.run_coroutine_threadsafe(_pump(hub, live), hub.loop)
    return live


async def _pump(hub: Hub, live: FoxgloveLive) -> None:
    """Feed ``live`` each machine's events from its feed's ring, while a Foxglove client is connected:
    with none, nothing is converted, and one that connects has each machine start from a snapshot
    (as a machine that fell behind the ring does)."""
    fed: dict[str, int] = {}  # machine -> the seq of the last event fed
    while True:
        if not live.watched():
            fed.clear()
            await asyncio.sleep(POLL_SECONDS)
            continue
        for entry in hub.machines():
            last = fed.get(entry.name)
            lines = entry.feed.encoded_from(last + 1, BATCH) if last is not None else None
            if lines is None:
                seq, frame = entry.feed.snapshot()
                status = loads(frame)["status"]
                live.event({"kind": "snapshot", "machine": entry.name, "seq": seq, "t": status.get("last_t") or 0.0,
                            "run": status.get("run"), "path": status.get("root_path") or "", "status": status})
                fed[entry.name] = seq
                continue
            for line in lines:
                event = loads(line)
                live.event(event)
                fed[entry.name] = event["seq"]
        await asyncio.sleep(POLL_SECONDS)
