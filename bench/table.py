"""The table a benchmark prints: one row per measure, its target, what was measured and whether the
target was met, then how fast this computer runs Python as the table is printed."""

import statistics
import time
from typing import Optional, Sequence

PACE_STEPS = 1_000_000


def verdict(met: Optional[bool]) -> str:
    """The result column: empty for a row shown for information (no target)."""
    return "" if met is None else ("met" if met else "MISSED")


def print_table(title: str, rows: Sequence[tuple[str, str, str, str]], measured: str = "median") -> None:
    """``rows``: (measure, target, measured, result) as text, each column as wide as its widest cell."""
    header = ("measure", "target", measured, "result")
    widths = [max(len(cells[i]) for cells in [header, *rows]) for i in range(3)]
    print(title)
    for cells in [header, None, *rows]:
        if cells is None:
            print("-" * (sum(widths) + 14))
            continue
        name, target, value, result = cells
        print("%-*s  %*s  %*s  %s" % (widths[0], name, widths[1], target, widths[2], value, result), flush=True)
    print("this computer now: a reference Python loop of %d steps takes %.1f ms (median of 5)"
          % (PACE_STEPS, computer_pace_ms()), flush=True)


def computer_pace_ms() -> float:
    """The time of a fixed pure-Python loop. This shared virtual machine's speed varies from day to
    day (the two-state loop measured 75,000 transitions/s on one day, 144,000 on the next, same code):
    tables of different days are compared by this line, which tells a slower computer from a slower
    change."""
    def once() -> float:
        start = time.perf_counter()
        total = 0
        for step in range(PACE_STEPS):
            total += step % 7
        return time.perf_counter() - start

    return 1000 * statistics.median(once() for _ in range(5))
