"""What the programs' stop and resume tests share (apps/tethered_pair/check_stop.py,
apps/tethered_pair/check_resume.py, apps/sweep/tests/check_stop.py): a list of the failed
checks, and the whole-line check of a stopped or killed run's CSV files."""

import os
import sys

failures = []


def check(cond, what):
    """Records `what` as failed (and prints it) unless `cond`; returns `cond`."""
    if not cond:
        failures.append(what)
        print("FAIL: " + what, file=sys.stderr)
    return cond


def check_csv(path):
    """Ends with a newline, every row has the header's column count. Returns (rows, last row)."""
    with open(path, "rb") as f:
        data = f.read()
    name = os.path.relpath(path)
    if not check(data.endswith(b"\n"), "%s does not end with a newline (a row cut short)" % name):
        return 0, None
    lines = data.decode().split("\n")[:-1]
    columns = lines[0].count(",") + 1
    bad = [i + 1 for i, line in enumerate(lines) if line.count(",") + 1 != columns]
    check(not bad, "%s: rows %s do not have the header's %d columns" % (name, bad[:5], columns))
    return len(lines) - 1, lines[-1].split(",") if len(lines) > 1 else None
