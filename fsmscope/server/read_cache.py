"""A machine's answers to reads that a page asks again and again (its summary, its timeline), kept by
what they depend on (the machine's last event, the question), so that asking again with nothing new
costs a lookup and no work: the same bytes, the same ETag, and 304 to an If-None-Match that has them."""

from __future__ import annotations

import collections
import hashlib
from dataclasses import dataclass
from typing import Hashable

from fastapi import Request
from fastapi.responses import Response

SIZE = 32  # answers kept per machine (the newest used)


@dataclass(frozen=True)
class Cached:
    body: bytes
    etag: str

    def response(self, request: Request) -> Response:
        """200 with the body, or 304 when the client has it (If-None-Match); either with the ETag."""
        headers = {"ETag": self.etag, "Cache-Control": "no-cache"}
        if self.etag in (tag.strip() for tag in request.headers.get("if-none-match", "").split(",")):
            return Response(status_code=304, headers=headers)
        return Response(self.body, media_type="application/json", headers=headers)


def cached(body: bytes) -> Cached:
    return Cached(body, '"%s"' % hashlib.blake2b(body, digest_size=12).hexdigest())


class Answers:
    """The newest ``SIZE`` answers of one machine, by key (used on the loop only)."""

    def __init__(self) -> None:
        self._kept: collections.OrderedDict[Hashable, Cached] = collections.OrderedDict()

    def get(self, key: Hashable) -> Cached | None:
        found = self._kept.get(key)
        if found is not None:
            self._kept.move_to_end(key)
        return found

    def put(self, key: Hashable, answer: Cached) -> None:
        self._kept[key] = answer
        self._kept.move_to_end(key)
        while len(self._kept) > SIZE:
            self._kept.popitem(last=False)
