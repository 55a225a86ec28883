"""What a machine's ``structure`` events say about each container path, for readers of a log.

Replay needs one fact the other events leave implicit: which kind of container a path
is (a StateMachine prints different lines from a Concurrence).
"""

from __future__ import annotations

from ..observation.schema import container_kind
from ..observation.structure import containers


class StructureIndex:
    """Per machine, per container path: its structure node (updated by ``structure`` events)."""

    def __init__(self) -> None:
        self._nodes: dict[tuple[str, str], dict] = {}

    def apply(self, event: dict) -> None:
        if event.get("kind") == "structure":
            self.add(event["machine"], event["root"])
        elif event.get("kind") == "snapshot":
            root = (event.get("status") or {}).get("structure")
            if root:
                self.add(event["machine"], root)

    def add(self, machine: str, root: dict) -> None:
        for node in containers(root):
            self._nodes[(machine, node["path"])] = node

    def node(self, machine: str, path: str) -> dict | None:
        return self._nodes.get((machine, path))

    def container_type(self, event: dict) -> str:
        """The container class behind ``event["path"]``; guessed from the event without a structure."""
        node = self._nodes.get((event["machine"], event["path"]))
        if node is not None:
            return container_kind(node)
        if event.get("kind") == "transition" and event.get("to") is None:
            return "Concurrence"
        if event.get("kind") == "terminate" and "outcomes" in event:
            return "Concurrence"
        if event.get("kind") == "transition" and event.get("from") == event.get("to"):
            return "Iterator"
        return "StateMachine"
