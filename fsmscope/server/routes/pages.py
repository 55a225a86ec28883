"""The pages: the dashboard, the API's own documentation page, health, who the token makes its bearer,
and where the 3D view is."""

from __future__ import annotations

import os

from typing import Annotated

from fastapi import APIRouter, Depends, Request
from fastapi.openapi.docs import get_swagger_ui_html
from fastapi.responses import FileResponse, HTMLResponse, Response

from .. import models
from ..auth import require_token
from ..static_files import static_dir
from .deps import AUTH, READ, READ_ERRORS

router = APIRouter()

_PLACEHOLDER = ("<!doctype html><meta charset=utf-8><title>fsmscope</title>"
                "<p>fsmscope server is running; the dashboard (fsmscope/static/index.html) is not installed. "
                "See <a href=/docs>/docs</a>.</p>")


def _page(filename: str) -> Response:
    """A page of the dashboard: it holds no data; it takes the token from its URL (fsmscope/static/token.js)."""
    root = static_dir()
    if root and os.path.isfile(os.path.join(root, filename)):
        return FileResponse(os.path.join(root, filename), headers={"Cache-Control": "no-cache"})
    return HTMLResponse(_PLACEHOLDER)


@router.get("/", include_in_schema=False)
async def index() -> Response:
    return _page("index.html")


@router.get("/fleet", include_in_schema=False)
async def fleet() -> Response:
    """The fleet overview: a tile per machine (fsmscope/static/fleet.js)."""
    return _page("fleet.html")


@router.get("/docs", include_in_schema=False)
async def docs(request: Request) -> HTMLResponse:
    """OpenAPI's page, with Swagger UI served from the swagger-ui-bundle package (mounted at
    /docs-assets by the app): a robot's network reaches no CDN, so FastAPI's default page would
    stay blank there."""
    return get_swagger_ui_html(openapi_url=request.app.openapi_url, title=request.app.title + " API",
                               swagger_js_url="/docs-assets/swagger-ui-bundle.js",
                               swagger_css_url="/docs-assets/swagger-ui.css",
                               swagger_favicon_url="/docs-assets/favicon-32x32.png")


@router.get("/api/health", response_model=models.Health, tags=["meta"])
async def health() -> models.Health:
    return models.Health(ok=True)


@router.get("/api/scene", response_model=models.Scene, dependencies=AUTH + READ, responses=READ_ERRORS,
            tags=["meta"])
async def scene(request: Request) -> models.Scene:
    return models.Scene(url=request.app.state.settings.scene_url)


@router.get("/api/session", response_model=models.Session, dependencies=READ, responses=READ_ERRORS, tags=["meta"],
            description="What the request's token lets it do: the page hides the controls of a viewer.")
async def session(role: Annotated[str, Depends(require_token)]) -> models.Session:
    return models.Session(role=role)
