"""The debugger's cost (issue 10): the bare two-state loop of bench/runtime.py with no debugger, with a
debugger attached and idle (no breakpoint, not paused: how a served machine is until someone debugs it),
and with a breakpoint whose condition never holds, so that every step goes through both gates. Target:
the idle debugger costs <= 5 %. Medians of ``--runs`` runs after one unmeasured run of each, the
conditions alternated so that a machine getting slower or faster weighs on each alike.

    .venv/bin/python bench/debugger.py [--runs 15]
"""

import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import fsm  # noqa: E402
from fsm.debugging import Debugger  # noqa: E402
from runtime import two_state_loop  # noqa: E402
from table import print_table, verdict  # noqa: E402

CONDITIONS = ("no debugger", "debugger attached, idle", "a breakpoint whose condition never holds")


def once(condition: str) -> float:
    machine, run = two_state_loop()
    debugger = None
    if condition != CONDITIONS[0]:
        debugger = Debugger(machine)
    if condition == CONDITIONS[2]:
        machine.userdata.never = False
        debugger.set_breakpoints([{"state": debugger.root_path + "/A", "at": "after", "when": "never"}])
    start = time.perf_counter()
    count = run()
    elapsed = time.perf_counter() - start
    if debugger is not None:
        debugger.detach()
    return count / elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args()
    fsm.set_loggers(*[lambda message: None] * 4)
    for condition in CONDITIONS:  # warm-up: the first runs of a process are the slowest
        once(condition)
    rates: dict[str, list[float]] = {c: [] for c in CONDITIONS}
    for _ in range(args.runs):
        for condition in CONDITIONS:
            rates[condition].append(once(condition))
    base = statistics.median(rates[CONDITIONS[0]])
    rows = []
    for condition in CONDITIONS:
        rate = statistics.median(rates[condition])
        targeted = condition == CONDITIONS[1]
        rows.append((condition, "<= 5 % lower" if targeted else "", "%.0f/s (%+.1f %%)" % (rate, (rate / base - 1) * 100),
                     verdict(rate >= 0.95 * base) if targeted else ""))
    print_table("fsmscope debugger: transitions/s of the two-state loop, %d runs" % args.runs, rows)


if __name__ == "__main__":
    main()
