"""A subscription to one ROS 2 topic: a DDS reader and the thread that hands each message on.

The thread waits on the reader (new data, a publisher matched or gone, a publisher whose QoS does
not fit) and on a guard that ``close`` sets. Each message is taken alone and decoded alone, so one
that does not decode is counted and said (``undecodable``, ``problems``) and the next ones still
arrive. A publisher is its participant (one ROS 2 process, or one context of it): ``on_publishers``
gets the set whenever it changes; a publisher that closes goes at once, one that is killed when
its participant's lease runs out (Cyclone DDS's default 10 s, Fast DDS's 20 s: the robot's setting).
"""

from __future__ import annotations

import collections
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

from cyclonedds.core import DDSException, DDSStatus, GuardCondition, InstanceState, ReadCondition, SampleState, ViewState, WaitSet
from cyclonedds.domain import DomainParticipant
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from fsmscope.ros2.dds import POLICY_NAMES, READER_QOS, delete
from fsmscope.ros2.messages import to_fields
from fsmscope.ros2.names import dds_type, ros_type

MAX_PROBLEMS = 100
# How long a publisher on the topic may stay unmatched before it is said not to fit: matching
# follows discovery by a few milliseconds on a network, by more under load.
UNMATCHED_GRACE = 2.0
_WAKE = duration(milliseconds=250)


@dataclass(frozen=True)
class Received:
    """One message as it arrived: the topic, the publisher's participant, ``time.time()`` on receipt,
    the message as a plain dict, and its stamp in seconds (``header.stamp``, or the message's own
    ``stamp`` as rcl_interfaces/Log has it; None for a message with neither)."""

    topic: str
    publisher: str
    t: float
    fields: dict[str, Any]
    stamp: float | None


def _stamp(fields: dict[str, Any]) -> float | None:
    stamp = fields.get("header", {}).get("stamp") if isinstance(fields.get("header"), dict) else fields.get("stamp")
    if isinstance(stamp, dict) and "sec" in stamp and "nanosec" in stamp:
        return stamp["sec"] + stamp["nanosec"] * 1e-9
    return None


class Subscription:
    """Messages of one type on one topic, handed to ``on_message`` from the subscription's thread."""

    def __init__(self, participant: DomainParticipant, dds_topic: Topic, topic: str, type_name: str,
                 publications: Callable[[str], list[Any]], on_message: Callable[[Received], None],
                 on_publishers: Callable[[list[str]], None] | None = None) -> None:
        """A reader of ``dds_topic`` (``topic``'s, of ``type_name``'s class) in ``participant``;
        ``publications(topic)`` lists the writers discovered on the topic (Node.publications)."""
        self.topic = topic
        self.type_name = type_name
        self.undecodable = 0
        self._problems: collections.deque[str] = collections.deque(maxlen=MAX_PROBLEMS)
        self._participant = participant
        self._publications = publications
        self._on_message = on_message
        self._on_publishers = on_publishers
        self._writers: dict[int, tuple[str, Any]] = {}   # matched writer's handle -> (participant, writer key)
        self._publishers: list[str] = []
        self._unmatched_since: dict[Any, float] = {}
        self._said_unmatched: set[Any] = set()
        self._incompatible = 0
        self._reader = DataReader(participant, dds_topic, qos=READER_QOS)
        self._reader.set_status_mask(DDSStatus.SubscriptionMatched | DDSStatus.RequestedIncompatibleQos)
        self._closed = threading.Event()
        self._guard = GuardCondition(participant)
        self._waitset = WaitSet(participant)
        self._waitset.attach(ReadCondition(self._reader, SampleState.NotRead | ViewState.Any | InstanceState.Any))
        self._waitset.attach(self._reader)
        self._waitset.attach(self._guard)
        self._thread = threading.Thread(target=self._run, name=f"ros2 {topic}", daemon=True)
        self._thread.start()

    @property
    def problems(self) -> list[str]:
        """What did not arrive and why (the last MAX_PROBLEMS), oldest first."""
        return list(self._problems)

    @property
    def publishers(self) -> list[str]:
        """The participants whose writers are matched now."""
        return list(self._publishers)

    def close(self) -> None:
        """Stop the thread and delete the reader; no callback runs after this returns (unless called
        from a callback, which returns at once and lets the thread end)."""
        if self._closed.is_set():
            return
        self._closed.set()
        self._guard.set(True)
        if threading.current_thread() is not self._thread:
            self._thread.join()
            delete(self._waitset, self._reader, self._guard)

    def _say(self, problem: str) -> None:
        self._problems.append(problem)

    def _run(self) -> None:
        next_check = 0.0
        while not self._closed.is_set():
            self._waitset.wait(_WAKE)
            if self._closed.is_set():
                break
            self._take_all()
            self._refresh_publishers()
            if time.monotonic() >= next_check:
                next_check = time.monotonic() + 1.0
                self._check_unmatched()

    def _take_all(self) -> None:
        while not self._closed.is_set():
            try:
                samples = self._reader.take(N=1)
            except DDSException as exc:  # the reader itself is gone (its participant deleted)
                self._say(f"the reader of {self.topic} stopped: {exc}")
                self._closed.set()
                return
            except Exception as exc:  # taken, then decoded in Python: one message lost, said
                self.undecodable += 1
                self._say(f"a message on {self.topic} did not decode as {self.type_name}: {type(exc).__name__}: {exc}")
                continue
            if not samples:
                return
            sample = samples[0]
            if not sample.sample_info.valid_data:
                continue  # a writer's unregistration, not a message
            fields = to_fields(sample)
            handle = sample.sample_info.publication_handle
            publisher = self._writers[handle][0] if handle in self._writers else self._participant_of(handle)
            received = Received(self.topic, publisher, time.time(), fields, _stamp(fields))
            try:
                self._on_message(received)
            except Exception as exc:
                self._say(f"on_message raised {type(exc).__name__}: {exc}")

    def _participant_of(self, handle: int) -> str:
        data = self._reader.get_matched_publication_data(handle)
        return str(data.participant_key) if data is not None else f"writer {handle:x}"

    def _refresh_publishers(self) -> None:
        self._reader.get_subscription_matched_status()  # resets the status the waitset woke on
        matched = _matched_publications(self._reader)
        for handle in matched - set(self._writers):
            data = self._reader.get_matched_publication_data(handle)
            if data is not None:
                self._writers[handle] = (str(data.participant_key), data.key)
        for handle in set(self._writers) - matched:
            del self._writers[handle]
        publishers = sorted({participant for participant, _ in self._writers.values()})
        if publishers != self._publishers:
            self._publishers = publishers
            if self._on_publishers is not None:
                try:
                    self._on_publishers(list(publishers))
                except Exception as exc:
                    self._say(f"on_publishers raised {type(exc).__name__}: {exc}")

    def _check_unmatched(self) -> None:
        """Say which publishers on the topic this reader does not receive, and why when DDS tells."""
        status = self._reader.get_requested_incompatible_qos_status()
        if status.total_count > self._incompatible:
            self._incompatible = status.total_count
            policy = POLICY_NAMES.get(status.last_policy_id, f"policy {status.last_policy_id}")
            self._say(f"a publisher on {self.topic} does not match this reader by DDS's {policy} policy (fsmscope "
                      f"reads {self.type_name}, reliable, volatile): its messages are not received")
        matched = {key for _, key in self._writers.values()}
        now = time.monotonic()
        ours = dds_type(self.type_name)
        seen = set()
        for publication in self._publications(self.topic):
            if publication.key in matched or publication.participant_key == self._participant.guid:
                continue
            seen.add(publication.key)
            since = self._unmatched_since.setdefault(publication.key, now)
            if now - since < UNMATCHED_GRACE or publication.key in self._said_unmatched:
                continue
            self._said_unmatched.add(publication.key)
            if publication.type_name != ours:
                self._say(f"participant {publication.participant_key} publishes {self.topic} as "
                          f"{ros_type(publication.type_name)}, not {self.type_name}: not received")
            else:
                self._say(f"participant {publication.participant_key} publishes {self.topic} as {self.type_name} "
                          f"but its writer does not match ours (its type's layout or its QoS differs): not received")
        for key in set(self._unmatched_since) - seen:
            del self._unmatched_since[key]


def _matched_publications(reader: Any) -> set[int]:
    """The instance handles of the writers ``reader`` matches. cyclonedds 11.0.1 counts them, then
    lists them into an array of that count, and indexes past its end (IndexError) when a writer
    matched in between: asked again, it counts that writer too."""
    while True:
        try:
            return set(reader.get_matched_publications())
        except IndexError:
            continue
