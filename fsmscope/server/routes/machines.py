"""What the dashboard reads about machines: the list, a machine's structure, its graph (its status: routes/history.py).
Each read is charged to its client's budget (fsmscope/server/read_budget.py)."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, HTTPException, Query
from fastapi.responses import Response

from fsm.observation.structure import node_at

from .. import graph, models
from .deps import AUTH, READ, READ_ERRORS, HubDep, Machine, ReadMeter

router = APIRouter(dependencies=AUTH, tags=["machines"])


@router.get("/api/machines", response_model=list[models.MachineInfo], responses=READ_ERRORS, dependencies=READ)
async def list_machines(hub: HubDep) -> list[dict]:
    out = []
    for entry in hub.machines():
        status = entry.feed.status
        controls, origin = entry.controls, entry.origin
        capabilities = controls.capabilities()
        out.append({"name": entry.name, "running": entry.running(), "outcome": status.outcome,
                    "last_seq": status.last_seq, "root_path": status.root_path,
                    "can_start": capabilities.can("start"), "controllable": capabilities.unavailable is None,
                    "can_hold": capabilities.can("hold"), "held": bool(controls.held), "cannot": dict(capabilities.cannot),
                    "source": origin.source, "connected": origin.connected, "rejected": origin.rejected,
                    "replay": origin.replay, "script": origin.script})
    return out


@router.get("/api/machines/{name}/structure", response_model=models.StructureNode, responses=READ_ERRORS,
            dependencies=READ)
async def structure(entry: Machine) -> Any:
    root = entry.feed.status.structure
    if root is None:
        raise HTTPException(404, "machine %r has no structure yet" % entry.name)
    return root


@router.get("/api/machines/{name}/graph.svg",
            responses={**READ_ERRORS, 200: {"content": {"image/svg+xml": {}}, "description": "the graph"}})
async def graph_svg(entry: Machine, meter: ReadMeter, expand: Annotated[list[str] | None, Query(max_length=200)] = None) -> Response:
    root = entry.feed.status.structure
    if root is None:
        raise HTTPException(404, "machine %r has no structure yet" % entry.name)
    key, n_states = entry.structure_info()
    for path in expand or ():
        node = node_at(root, path)
        if node is None or not node.get("container"):
            raise HTTPException(404, "no container at %r" % path)
    svg = await meter.in_thread(graph.render, root, key, expand, n_states)
    return Response(svg, media_type="image/svg+xml", headers={"Cache-Control": "no-cache"})
