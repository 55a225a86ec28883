"""Walking a machine's structure, in both its forms: the running tree of containers and states,
and the nested dict a ``structure`` event describes it with (docs/events.md).

Every tool that goes over a machine's states does it through here, so that "is this a
container", "is this a Concurrence" and "which state is at this path" each have one answer.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, Iterator

# The running tree.


def is_container(state: Any) -> bool:
    """SMACH's test: whatever has children is a container (a user's own container class too)."""
    return hasattr(state, "get_children")


def children(state: Any) -> dict:
    """A state's children by label; none for a leaf."""
    return state.get_children() if is_container(state) else {}


def state_at(root: Any, labels: Iterable[str]) -> Any:
    """The state reached from ``root`` through these child labels; None when there is none."""
    state = root
    for label in labels:
        below = children(state)
        if label not in below:
            return None
        state = below[label]
    return state


def is_concurrence(container: Any) -> bool:
    """A Concurrence, fsm's or the original smach's (or a subclass of either), told by its shape: an
    outcome map and its children's outcomes. It starts all its children, so it has no initial state
    to set."""
    return hasattr(container, "_child_outcomes") and hasattr(container, "_outcome_map")


# The ``structure`` event's tree: nodes with label, path, container and, for a container, children.

def walk(root: dict, descend: Callable[[dict], bool] | None = None) -> Iterator[tuple[dict, int]]:
    """Every node with its depth (the root's is 0), parents first and children in their order.

    Only a container's children are visited, and only when ``descend(container)`` is true (always
    without ``descend``).
    """
    stack = [(root, 0)]
    while stack:
        node, depth = stack.pop()
        yield node, depth
        below = node.get("children") if node.get("container") else None
        if below and (descend is None or descend(node)):
            stack.extend((child, depth + 1) for child in reversed(below))


def containers(root: dict, descend: Callable[[dict], bool] | None = None) -> Iterator[dict]:
    """The container nodes of ``walk``, in its order."""
    return (node for node, _ in walk(root, descend) if node.get("container"))


def count(root: dict | None) -> int:
    """How many states (containers included) a structure holds; 0 for none."""
    return sum(1 for _ in walk(root)) if root else 0


def node_at(root: dict | None, path: str) -> dict | None:
    """The node at ``path``, searching only the containers whose path leads there."""
    if root is None:
        return None
    for node, _ in walk(root, lambda container: path.startswith(container["path"] + "/")):
        if node["path"] == path:
            return node
    return None
