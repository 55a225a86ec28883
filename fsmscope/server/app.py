"""The FastAPI application: its configuration, error answers, middleware and routers (docs/api.md).

The routes are in fsmscope/server/routes/, one router per concern; what they share (the hub, the
settings) is on ``app.state`` and reaches them as dependencies (fsmscope/server/routes/deps.py).
"""

from __future__ import annotations

import asyncio
import contextlib
import os
from typing import Any, AsyncIterator, Callable

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from fastapi.staticfiles import StaticFiles
from starlette.exceptions import HTTPException as StarletteHTTPException
from swagger_ui_bundle import swagger_ui_path

from fsm.control.controls import Refused

from .hub import Hub
from .lease import Deadman, Leases
from .lease_control import LeaseControl
from .middleware import SecurityMiddleware
from .overview import Overview
from .read_budget import ReadBudget
from .refusals import Refusals
from .routes import control, debug, history, ingest, lease, machines, overview, pages, scene, stream, timeline
from .settings import Settings
from .static_files import static_dir


def create_app(hub: Hub, token: str | None, host: str = "127.0.0.1", port: int | None = None,
               title: str = "fsmscope", scene_url: str | None = None,
               show_pose: Callable[[str, dict | None], None] | None = None, viewer_token: str | None = None,
               deadman: Deadman | None = None, reads: ReadBudget | None = None) -> FastAPI:
    """The dashboard's app; ``scene_url``: a 3D view served beside it (the sim demo's viser), or None;
    ``show_pose(view, pose)``: what draws a pose's fields in one page's view of it (None: back to live), for
    POST /api/scene/pose; ``viewer_token``: a second token that may watch and not control (fsmscope/server/auth.py);
    ``deadman``: what a machine does when its operator's page goes silent (fsmscope/server/lease.py; default: pause
    after 3 s); ``reads``: what each client's reads may cost the server (fsmscope/server/read_budget.py; default: 2 %
    of a core)."""
    leases = LeaseControl(hub, Leases(deadman or Deadman()))

    @contextlib.asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        hub.bind_loop(asyncio.get_running_loop())
        deadman_task = asyncio.create_task(leases.run_deadman())
        yield
        deadman_task.cancel()
        await hub.close()

    app = _App(title=title, version="1", lifespan=lifespan, docs_url=None, redoc_url=None,
               description="Live view and control of fsm state machines (docs/api.md).")
    app.state.settings = Settings(token=token, viewer_token=viewer_token, host=host, port=port, scene_url=scene_url)
    app.state.hub = hub
    app.state.leases = leases
    app.state.overview = Overview(hub)
    app.state.reads = reads or ReadBudget()
    app.state.refusals = Refusals()
    app.state.show_pose = show_pose
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(Exception, _unexpected_error)
    app.add_exception_handler(Refused, _refused)
    app.mount("/docs-assets", StaticFiles(directory=swagger_ui_path), name="docs-assets")  # for pages.docs
    for module in (pages, machines, overview, history, timeline, control, debug, lease, scene, stream, ingest):
        app.include_router(module.router)
    root = static_dir()
    if root and os.path.isdir(root):
        app.mount("/static", StaticFiles(directory=root), name="static")
        app.mount("/", StaticFiles(directory=root), name="static-root")
    return app


class _App(FastAPI):
    """FastAPI with the security middleware outside everything, even the handler that answers
    500: every response, errors included, goes through the Host check and gets its headers.
    Inside it, the stream's ``KeepServerSend`` sees each websocket's ``send`` as the server gave it."""

    def build_middleware_stack(self) -> Any:
        return SecurityMiddleware(stream.KeepServerSend(super().build_middleware_stack()), self.state.settings)


# Errors: always JSON {"detail": str}, never a 500.
async def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
    return JSONResponse({"detail": str(exc.detail)}, status_code=exc.status_code, headers=exc.headers)


async def _validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
    return JSONResponse({"detail": _validation_message(exc)}, status_code=422)


async def _unexpected_error(request: Request, exc: Exception) -> JSONResponse:
    return JSONResponse({"detail": "internal error (%s)" % type(exc).__name__}, status_code=500)


async def _refused(request: Request, exc: Refused) -> JSONResponse:
    """What a machine's controls or its history refused (fsm/control/controls.py), with its status."""
    return JSONResponse({"detail": exc.message}, status_code=exc.status)


def _validation_message(exc: RequestValidationError) -> str:
    parts = []
    for err in exc.errors()[:5]:
        loc = ".".join(str(x) for x in err.get("loc", ()) if x != "body") or "body"
        parts.append("%s: %s" % (loc, err.get("msg", "invalid")))
    return "; ".join(parts) or "invalid request"
