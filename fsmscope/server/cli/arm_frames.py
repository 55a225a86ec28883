"""A pose event's frames for Foxglove (``export --mcap``, ``--foxglove``): the composition of the
simulator's forward kinematics (sim) with interop's frames."""

from __future__ import annotations

from typing import Callable


def arm_frames() -> Callable[[dict], list] | None:
    """A pose event's frames: the demo arm's every body by forward kinematics (sim), falling back to
    the pose's free bodies for a pose of another robot; None without the simulator installed."""
    try:
        from fsmscope.sim.pose import PoseFrames
    except ImportError:
        return None
    from fsmscope.interop.channels import body_frames

    arm = PoseFrames()

    def frames(event: dict) -> list:
        try:
            return arm(event)
        except ValueError:  # a joint the demo's arm does not have
            return body_frames(event)
    return frames
