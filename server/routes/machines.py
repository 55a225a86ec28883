"""What the dashboard reads about machines: the list, a machine's structure, its graph (its status: routes/history.py)."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, HTTPException, Query
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import Response

from fsm.observation.structure import node_at

from .. import graph, models
from .deps import AUTH, ERRORS, HubDep, Machine

router = APIRouter(dependencies=AUTH, tags=["machines"])


@router.get("/api/machines", response_model=list[models.MachineInfo], responses=ERRORS)
async def list_machines(hub: HubDep) -> list[dict]:
    out = []
    for entry in hub.machines():
        status = entry.status
        handle = entry.handle
        remote = entry.remote if entry.remote is not None and entry.remote.connected else None
        can_start = handle.can_start if handle is not None else remote is not None and remote.can_start
        out.append({"name": entry.name, "running": entry.running(), "outcome": status.outcome,
                    "last_seq": status.last_seq, "root_path": status.root_path, "can_start": bool(can_start),
                    "controllable": handle is not None or remote is not None,
                    "can_hold": bool(handle is not None and handle.holder is not None),
                    "held": bool(handle is not None and handle.held),
                    "source": entry.source, "connected": entry.connected, "rejected": entry.rejected,
                    "replay": entry.replay})
    return out


@router.get("/api/machines/{name}/structure", response_model=models.StructureNode, responses=ERRORS)
async def structure(entry: Machine) -> Any:
    if entry.status.structure is None:
        raise HTTPException(404, "machine %r has no structure yet" % entry.name)
    return entry.status.structure


@router.get("/api/machines/{name}/graph.svg",
            responses={**ERRORS, 200: {"content": {"image/svg+xml": {}}, "description": "the graph"}})
async def graph_svg(entry: Machine, expand: Annotated[list[str] | None, Query(max_length=200)] = None) -> Response:
    root = entry.status.structure
    if root is None:
        raise HTTPException(404, "machine %r has no structure yet" % entry.name)
    key, n_states = entry.structure_info()
    for path in expand or ():
        node = node_at(root, path)
        if node is None or not node.get("container"):
            raise HTTPException(404, "no container at %r" % path)
    svg = await run_in_threadpool(graph.render, root, key, expand, n_states)
    return Response(svg, media_type="image/svg+xml", headers={"Cache-Control": "no-cache"})
