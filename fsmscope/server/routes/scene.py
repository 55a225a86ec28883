"""Show a recorded pose in one page's 3D view (that page looking back at an instant), or the live robot again.

Looking back is a page's own business: the page names its own view (the random id its frame of the
3D view connected with, fsmscope/static/scene.js), and only that view's browsers are shown the pose; every
other page's view stays as it is. The server draws nothing itself: the composition root
(fsmscope/server/cli/) gives the app a ``show_pose(view, pose)`` callable when it serves a 3D view (the
demo's ``Scene.show_pose``), so ``server`` never imports ``sim``.
"""

from __future__ import annotations

from typing import Any, Callable

from fastapi import APIRouter, HTTPException, Request
from fastapi.concurrency import run_in_threadpool

from fsm.observation.schema import KINDS, event, validate

from .. import models
from .deps import AUTH, ERRORS

router = APIRouter(dependencies=AUTH, responses=ERRORS, tags=["control"])

POSE_FIELDS = tuple(f.name for f in KINDS["pose"].fields)


def pose_problem(pose: dict[str, Any]) -> str | None:
    """What is wrong with ``pose`` as a pose event's fields, in the schema's words; None when it fits."""
    extra = sorted(set(pose) - set(POSE_FIELDS))
    if extra:
        return "pose may hold only %s, not %s" % (" and ".join(POSE_FIELDS),
                                                  ", ".join(repr(k[:50]) for k in extra[:5]))
    return validate(event(0, 0.0, None, "scene", "pose", "/", pose))


@router.post("/api/scene/pose", response_model=models.ScenePoseShown,
             description="Draw a pose in the page's own 3D view (`view`) instead of the live robot (null: the live "
                         "robot again); no other page's view changes. 404 when this server has no 3D view.")
async def show_pose(request: Request, body: models.ScenePoseRequest) -> models.ScenePoseShown:
    show: Callable[[str, dict | None], None] | None = request.app.state.show_pose
    if show is None:
        raise HTTPException(404, "no 3D view")
    if body.pose is not None:
        problem = pose_problem(body.pose)
        if problem:
            raise HTTPException(422, problem)
    try:
        await run_in_threadpool(show, body.view, body.pose)
    except ValueError as exc:  # a joint or body the scene's model does not have
        raise HTTPException(422, str(exc)) from exc
    return models.ScenePoseShown(live=body.pose is None)
