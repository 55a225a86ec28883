"""The FastAPI application: REST, the websocket stream, ingest, static files (docs/api.md)."""

from __future__ import annotations

import asyncio
import contextlib
import importlib.util
import os
from typing import Annotated, Any

import orjson
from fastapi import Body, Depends, FastAPI, HTTPException, Path, Query, Request, WebSocket
from fastapi.concurrency import run_in_threadpool
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.websockets import WebSocketDisconnect
from swagger_ui_bundle import swagger_ui_path

from . import models
from .control import ControlError, find_node, publish
from .hub import Hub, MachineEntry
from .security import (SecurityMiddleware, Settings, deny_websocket, require_token, websocket_refusal,
                       websocket_subprotocol)

ERRORS = {code: {"model": models.Error} for code in (400, 401, 403, 404, 409, 413, 422)}
NAME = Path(min_length=1, max_length=200, description="machine name")
TOPIC = Path(min_length=1, max_length=200, pattern=r"^[A-Za-z0-9_.~/-]+$", description="topic name")


def static_dir() -> str | None:
    spec = importlib.util.find_spec("static")
    if spec is None or not spec.submodule_search_locations:
        return None
    return list(spec.submodule_search_locations)[0]


_PLACEHOLDER = ("<!doctype html><meta charset=utf-8><title>fsmscope</title>"
                "<p>fsmscope server is running; the dashboard (static/index.html) is not installed. "
                "See <a href=/docs>/docs</a>.</p>")


def _validation_message(exc: RequestValidationError) -> str:
    parts = []
    for err in exc.errors()[:5]:
        loc = ".".join(str(x) for x in err.get("loc", ()) if x != "body") or "body"
        parts.append("%s: %s" % (loc, err.get("msg", "invalid")))
    return "; ".join(parts) or "invalid request"


def _raw_abort(scope: dict) -> Any:
    """A way to drop a stalled socket without a clean close (which would wait for unsent data)."""
    send = scope.get("fsmscope.raw_send")
    protocol = getattr(send, "__self__", None)
    transport = getattr(protocol, "transport", None)
    if transport is None or not hasattr(transport, "abort"):
        return None
    return transport.abort


def create_app(hub: Hub, token: str | None, host: str = "127.0.0.1", port: int | None = None,
               title: str = "fsmscope", scene_url: str | None = None) -> FastAPI:
    """The dashboard's app; ``scene_url``: a 3D view served beside it (the sim demo's viser), or None."""
    settings = Settings(token=token, host=host, port=port)

    @contextlib.asynccontextmanager
    async def lifespan(app: FastAPI):
        hub.bind_loop(asyncio.get_running_loop())
        yield
        await hub.close()

    app = _App(title=title, version="1", lifespan=lifespan, docs_url=None, redoc_url=None,
               description="Live view and control of fsm state machines (docs/api.md).")
    app.state.settings = settings
    app.state.hub = hub

    # Errors: always JSON {"detail": str}, never a 500.
    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        return JSONResponse({"detail": str(exc.detail)}, status_code=exc.status_code, headers=exc.headers)

    @app.exception_handler(RequestValidationError)
    async def validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
        return JSONResponse({"detail": _validation_message(exc)}, status_code=422)

    @app.exception_handler(Exception)
    async def unexpected_error(request: Request, exc: Exception) -> JSONResponse:
        return JSONResponse({"detail": "internal error (%s)" % type(exc).__name__}, status_code=500)

    @app.exception_handler(ControlError)
    async def control_error(request: Request, exc: ControlError) -> JSONResponse:
        return JSONResponse({"detail": exc.message}, status_code=exc.status)

    auth = [Depends(require_token)]

    def machine(name: str) -> MachineEntry:
        hub.flush()
        entry = hub.get(name)
        if entry is None:
            raise HTTPException(404, "no machine named %r" % name)
        return entry

    def local(entry: MachineEntry) -> Any:
        if entry.handle is None:
            if entry.source == "replay":
                raise HTTPException(409, "machine %r is a recording being replayed: nothing to control" % entry.name)
            raise HTTPException(409, "machine %r runs in another process: control it there" % entry.name)
        return entry.handle

    def client_of(request: Request) -> str:
        return request.client.host if request.client else ""

    # Pages.
    @app.get("/", include_in_schema=False)
    async def index() -> Response:
        """The page holds no data; it takes the token from its URL (static/token.js)."""
        root = static_dir()
        if root and os.path.isfile(os.path.join(root, "index.html")):
            return FileResponse(os.path.join(root, "index.html"), headers={"Cache-Control": "no-cache"})
        return HTMLResponse(_PLACEHOLDER)

    # OpenAPI's page, with Swagger UI served from the swagger-ui-bundle package: a robot's
    # network reaches no CDN, so FastAPI's default page would stay blank there.
    app.mount("/docs-assets", StaticFiles(directory=swagger_ui_path), name="docs-assets")

    @app.get("/docs", include_in_schema=False)
    async def docs() -> HTMLResponse:
        return get_swagger_ui_html(openapi_url=app.openapi_url, title=title + " API",
                                   swagger_js_url="/docs-assets/swagger-ui-bundle.js",
                                   swagger_css_url="/docs-assets/swagger-ui.css",
                                   swagger_favicon_url="/docs-assets/favicon-32x32.png")

    # REST.
    @app.get("/api/health", response_model=models.Health, tags=["meta"])
    async def health() -> models.Health:
        return models.Health(ok=True)

    @app.get("/api/scene", response_model=models.Scene, dependencies=auth, responses=ERRORS, tags=["meta"])
    async def scene() -> models.Scene:
        return models.Scene(url=scene_url)

    @app.get("/api/machines", response_model=list[models.MachineInfo], dependencies=auth, responses=ERRORS,
             tags=["machines"])
    async def list_machines() -> list[dict]:
        hub.flush()
        out = []
        for entry in hub.machines():
            status = entry.status
            out.append({"name": entry.name, "running": entry.running(), "outcome": status.outcome,
                        "last_seq": status.last_seq, "root_path": status.root_path,
                        "can_start": bool(entry.handle is not None and entry.handle.can_start),
                        "can_hold": bool(entry.handle is not None and entry.handle.holder is not None),
                        "held": bool(entry.handle is not None and entry.handle.held),
                        "source": entry.source, "connected": entry.connected, "rejected": entry.rejected})
        return out

    @app.get("/api/machines/{name}/structure", response_model=models.StructureNode, dependencies=auth,
             responses=ERRORS, tags=["machines"])
    async def structure(name: Annotated[str, NAME]) -> Any:
        entry = machine(name)
        if entry.status.structure is None:
            raise HTTPException(404, "machine %r has no structure yet" % name)
        return entry.status.structure

    @app.get("/api/machines/{name}/status", response_model=models.MachineStatus, dependencies=auth,
             responses=ERRORS, tags=["machines"])
    async def status(name: Annotated[str, NAME]) -> Any:
        data = machine(name).status_dict()
        data.pop("structure", None)
        return data

    @app.get("/api/machines/{name}/graph.svg", dependencies=auth, tags=["machines"],
             responses={**ERRORS, 200: {"content": {"image/svg+xml": {}}, "description": "the graph"}})
    async def graph_svg(name: Annotated[str, NAME],
                        expand: Annotated[list[str] | None, Query(max_length=200)] = None) -> Response:
        from . import graph

        entry = machine(name)
        root = entry.status.structure
        if root is None:
            raise HTTPException(404, "machine %r has no structure yet" % name)
        key, n_states = entry.structure_info()
        for path in expand or ():
            node = find_node(root, path)
            if node is None or not node.get("container"):
                raise HTTPException(404, "no container at %r" % path)
        svg = await run_in_threadpool(graph.render, root, key, expand, n_states)
        return Response(svg, media_type="image/svg+xml", headers={"Cache-Control": "no-cache"})

    @app.post("/api/machines/{name}/preempt", status_code=202, response_model=models.SeqResponse,
              dependencies=auth, responses=ERRORS, tags=["control"])
    async def preempt(name: Annotated[str, NAME], request: Request,
                      body: Annotated[models.PreemptRequest | None, Body()] = None) -> models.SeqResponse:
        handle = local(machine(name))
        reason = body.reason if body is not None else None
        seq = await run_in_threadpool(handle.preempt, reason, client_of(request))
        return models.SeqResponse(seq=seq)

    @app.post("/api/machines/{name}/hold", status_code=202, response_model=models.SeqResponse,
              dependencies=auth, responses=ERRORS, tags=["control"],
              description="Let the current run finish, then start no other until the next start "
                          "(a machine its host runs in a loop, such as the demo's episodes; 409 otherwise).")
    async def hold(name: Annotated[str, NAME], request: Request,
                   body: Annotated[models.PreemptRequest | None, Body()] = None) -> models.SeqResponse:
        handle = local(machine(name))
        seq = await run_in_threadpool(handle.hold, body.reason if body is not None else None, client_of(request))
        return models.SeqResponse(seq=seq)

    @app.post("/api/machines/{name}/initial-state", response_model=models.SeqResponse, dependencies=auth,
              responses=ERRORS, tags=["control"])
    async def initial_state(name: Annotated[str, NAME], body: models.InitialStateRequest,
                            request: Request) -> models.SeqResponse:
        handle = local(machine(name))
        seq = await run_in_threadpool(handle.set_initial_state, body.path, list(body.states), dict(body.userdata),
                                      client_of(request))
        return models.SeqResponse(seq=seq)

    @app.post("/api/machines/{name}/start", status_code=202, response_model=models.SeqResponse,
              dependencies=auth, responses=ERRORS, tags=["control"])
    async def start(name: Annotated[str, NAME], request: Request,
                    body: Annotated[models.StartRequest | None, Body()] = None) -> models.SeqResponse:
        handle = local(machine(name))
        seq = await run_in_threadpool(handle.start, client_of(request))
        return models.SeqResponse(seq=seq)

    @app.post("/api/topics/{topic}", status_code=202, response_model=models.Delivered, dependencies=auth,
              responses=ERRORS, tags=["control"])
    async def publish_topic(topic: Annotated[str, TOPIC], request: Request,
                            message: Annotated[Any, Body(description="any JSON value: the message")] = None
                            ) -> models.Delivered:
        client = client_of(request)

        def do() -> int:
            delivered = publish(topic, message)
            for entry in hub.machines():
                if entry.handle is not None and entry.handle.is_running():
                    entry.handle.emit_control("publish", client, "accepted",
                                              params={"topic": topic, "delivered": delivered})
            return delivered

        return models.Delivered(delivered=await run_in_threadpool(do))

    # Websockets.
    @app.websocket("/api/machines/{name}/stream")
    async def stream(websocket: WebSocket, name: str) -> None:
        refusal = websocket_refusal(websocket)
        if refusal is not None:
            await deny_websocket(websocket, *refusal)
            return
        since_text = websocket.query_params.get("since")
        since = None
        if since_text is not None:
            try:
                since = int(since_text)
            except ValueError:
                await deny_websocket(websocket, 422, "since must be an integer")
                return
        hub.flush()
        entry = hub.get(name)
        if entry is None:
            await deny_websocket(websocket, 404, "no machine named %r" % name)
            return
        await websocket.accept(websocket_subprotocol(websocket))
        raw_send = websocket.scope.get("fsmscope.raw_send") or websocket._send

        async def send(frame: str) -> None:
            await raw_send({"type": "websocket.send", "text": frame})

        address = websocket.client.host if websocket.client else ""
        client = hub.subscribe(entry, since, _raw_abort(websocket.scope), address)
        sender = asyncio.ensure_future(hub.run_client(client, send))
        client.task = sender
        receiver = asyncio.ensure_future(_drain_incoming(websocket))
        try:
            await asyncio.wait([sender, receiver], return_when=asyncio.FIRST_COMPLETED)
        finally:
            for task in (sender, receiver):
                task.cancel()
            hub.unsubscribe(client)
            for task in (sender, receiver):
                with contextlib.suppress(BaseException):
                    await task

    @app.websocket("/api/ingest")
    async def ingest(websocket: WebSocket) -> None:
        refusal = websocket_refusal(websocket)
        if refusal is not None:
            await deny_websocket(websocket, *refusal)
            return
        await websocket.accept(websocket_subprotocol(websocket))
        fed: set[str] = set()  # the machines this publisher feeds: shown disconnected when it leaves
        try:
            while True:
                message = await websocket.receive()
                if message["type"] == "websocket.disconnect":
                    return
                data = message.get("text")
                if data is None:
                    data = message.get("bytes") or b""
                try:
                    events = orjson.loads(data)
                except orjson.JSONDecodeError:
                    await websocket.close(1007, "frames must be JSON arrays of events")
                    return
                if isinstance(events, dict):
                    events = [events]
                if not isinstance(events, list):
                    await websocket.close(1007, "frames must be JSON arrays of events")
                    return
                for event in events:
                    problem = hub.ingest(event)
                    if problem is None:
                        fed.add(event["machine"])
                        hub.get(event["machine"]).connected = True
                        continue
                    await websocket.send_text(orjson.dumps(
                        {"type": "rejected", "reason": problem, "machine": _field(event, "machine"),
                         "seq": _field(event, "seq")}).decode())
        except WebSocketDisconnect:
            return
        finally:
            for name in fed:
                entry = hub.get(name)
                if entry is not None and entry.source == "ingest":
                    entry.connected = False

    root = static_dir()
    if root and os.path.isdir(root):
        app.mount("/static", StaticFiles(directory=root), name="static")
        app.mount("/", StaticFiles(directory=root), name="static-root")
    return app


class _App(FastAPI):
    """FastAPI with the security middleware outside everything, even the handler that answers
    500: every response, errors included, goes through the Host check and gets its headers."""

    def build_middleware_stack(self) -> Any:
        return SecurityMiddleware(super().build_middleware_stack(), self.state.settings)


async def _drain_incoming(websocket: WebSocket) -> None:
    """Client-to-server messages are ignored; returns when the client leaves."""
    while True:
        message = await websocket.receive()
        if message["type"] == "websocket.disconnect":
            return


def _field(event: Any, name: str) -> Any:
    """A refused event's field, echoed back to its publisher only when it is a plain scalar."""
    value = event.get(name) if isinstance(event, dict) else None
    return value if type(value) in (str, int) else None
