"""Schema-driven fuzz of every REST endpoint (schemathesis strategies driven by hypothesis) against a real
uvicorn: never a 5xx, and every error is JSON {"detail": str}."""

import pytest
import schemathesis
from hypothesis import HealthCheck, given, settings

from fsmscope.server.app import create_app
from fsmscope.server.hub import Hub
from fsmscope.server.http_server import ServerThread
from server_support import nested_machine, two_state_machine

SCHEMA = schemathesis.openapi.from_dict(create_app(Hub(), "t").openapi())
OPERATIONS = [result.ok() for result in SCHEMA.get_all_operations()]


@pytest.fixture(scope="module")
def fuzz_server():
    srv = ServerThread().start()
    srv.hub.add_local(two_state_machine(), name="two")
    srv.hub.add_local(nested_machine(), name="n")
    yield srv
    srv.stop()


@pytest.mark.parametrize("operation", OPERATIONS, ids=[op.label for op in OPERATIONS])
def test_no_server_error(operation, fuzz_server):
    @given(case=operation.as_strategy())
    @settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck), database=None)
    def fuzz(case):
        for headers in ({"Authorization": "Bearer " + fuzz_server.token}, {}):
            response = case.call(base_url=fuzz_server.base_url, headers=headers, timeout=10)
            assert response.status_code < 500, (case.method, case.formatted_path, response.status_code,
                                                response.text)
            if response.status_code >= 400:
                assert isinstance(response.json()["detail"], str), response.text
    fuzz()
