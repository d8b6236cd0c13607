#!/usr/bin/env python3
"""kelp-sweep's checks: test_sweep.py KELP_SWEEP SMALL_SWEEP WORKDIR

- shards 0..2 of 3 merged give the unsharded table, byte for byte (CSV and Markdown);
- deleting one run's result and rerunning reruns that run only, and the table is unchanged;
- bad sweep files (unknown JSON path, empty axis, non-finite value, a value the scenario
  refuses, a bad --shard, nesting too deep, an index past an array's end, too many runs) are
  refused with exit status 3 and a message naming the path;
- plot_sweep.py draws the figure from the table.
"""
import json
import os
import shutil
import subprocess
import sys

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what, flush=True)
    return cond


def run(*args):
    p = subprocess.run(list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def read(path):
    with open(path, "rb") as f:
        return f.read()


def main(program, small, work):
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    full = os.path.join(work, "full")
    code, out, err = run(program, "--sweep", small, "--out", full, "--no-plot", "--quiet")
    print(out + err)
    check(code == 0, "unsharded sweep failed (%d)" % code)
    check("8 ran, 0 reused" in out, "unsharded sweep did not run 8 runs")
    table = read(os.path.join(full, "table.csv"))
    lines = table.decode().strip().split("\n")
    check(len(lines) == 5, "table.csv has %d lines, expected a header and 4 grid points" % len(lines))
    print(read(os.path.join(full, "table.md")).decode())

    shards = []
    for i in range(3):
        d = os.path.join(work, "shard-%d" % i)
        code, out, err = run(program, "--sweep", small, "--out", d, "--shard", "%d/3" % i,
                             "--quiet", "--jobs", "1")
        check(code == 0, "shard %d failed: %s" % (i, err))
        check(not os.path.exists(os.path.join(d, "table.csv")), "a shard wrote a table")
        shards.append(d)
    merged = os.path.join(work, "merged")
    code, out, err = run(program, "merge", *shards, "--out", merged, "--no-plot")
    check(code == 0, "merge failed: %s" % err)
    check(read(os.path.join(merged, "table.csv")) == table, "merged table.csv differs")
    check(read(os.path.join(merged, "table.md")) == read(os.path.join(full, "table.md")),
          "merged table.md differs")
    # A merge with a shard missing says so.
    code, out, err = run(program, "merge", *shards[:2], "--out", os.path.join(work, "partial"),
                         "--no-plot")
    check(code == 1 and "have no result" in err, "an incomplete merge was not refused")

    # Resume: one result deleted, one run again.
    runs = sorted(os.listdir(os.path.join(full, "runs")))
    check(len(runs) == 8, "%d result files, expected 8" % len(runs))
    os.remove(os.path.join(full, "runs", runs[3]))
    code, out, err = run(program, "--sweep", small, "--out", full, "--no-plot", "--quiet")
    check(code == 0 and "1 ran, 7 reused" in out, "resume did not rerun exactly one run: " + out)
    check(read(os.path.join(full, "table.csv")) == table, "the resumed table differs")

    # Bad sweep files.
    base = json.load(open(small))
    cases = [
        ("unknown path", {"axes": [{"path": "/tether/lenght", "values": [5]}]}, "/tether/lenght"),
        ("empty axis", {"axes": [{"path": "/tether/length", "values": []}]}, "/axes/0/values"),
        ("non-finite", '{"axes": [{"path": "/tether/length", "values": [5, 1e999]}]}',
         "/axes/0/values/1"),
        ("refused value", {"axes": [{"path": "/tether/length", "values": [-3]}]},
         "/tether/length"),
        ("bad pointer", {"axes": [{"path": "tether/length", "values": [5]}]}, "/axes/0/path"),
        ("bad seeds", {"seeds": [1, -2]}, "/seeds/1"),
        # Found by fuzz/fuzz_sweep: a file nested 100000 levels deep overflowed the stack, an
        # index past the end of an array allocated gigabytes, 10^7 runs ran out of time and
        # memory, and a pointer 100000 levels deep built a scenario as deep.
        ("nested too deep", '{"base": {"x": ' + "[" * 100000 + "]" * 100000 + "}}",
         "nested more than 64 levels"),
        ("index past the end",
         {"axes": [{"path": "/mission/waypoints/0/900000000", "values": [1]}]}, "/axes/0/path"),
        ("too many runs",
         {"axes": [{"path": "/duration", "values": list(range(1, 11))}] * 7}, "/axes/5/values"),
        ("pointer too deep", {"axes": [{"path": "/a" * 100000, "values": [1]}]}, "/axes/0/path"),
    ]
    for name, content, path in cases:
        f = os.path.join(work, "bad.json")
        with open(f, "w") as fh:
            fh.write(content if isinstance(content, str) else json.dumps(dict(base, **content)))
        code, out, err = run(program, "--sweep", f, "--out", os.path.join(work, "bad"),
                             "--no-plot", "--quiet")
        check(code == 3 and path in err, "%s: exit %d, message %r does not name %s"
              % (name, code, err.strip(), path))
    code, out, err = run(program, "--sweep", small, "--shard", "3/3", "--out",
                         os.path.join(work, "bad"))
    check(code == 3 and "--shard" in err, "--shard 3/3 accepted")

    # The figure.
    plot = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plot_sweep.py")
    python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
    check(subprocess.call([python, plot, full]) == 0, "plot_sweep.py failed")
    check(os.path.exists(os.path.join(full, "errors.png")), "no errors.png")

    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("kelp-sweep: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:4]))
