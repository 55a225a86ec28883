"""Tooling that drives fsmscope from outside, as a user or a browser would: shared by the tests,
the benchmarks (bench/) and docs/screenshot.py, the way Starlette ships ``starlette.testclient``.

Playwright is a test extra: only the functions that need it import it."""
