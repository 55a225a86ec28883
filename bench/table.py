"""The table a benchmark prints: one row per measure, its target, what was measured and whether the
target was met (bench/timetravel.py, bench/timetravel_browser.py and bench/live_rewind.py print it)."""

from typing import Optional, Sequence


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
