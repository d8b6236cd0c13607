#!/usr/bin/env python3
"""kelp-sweep's checks: test_sweep.py KELP_SWEEP SMALL_SWEEP WORKDIR

- shards 0..2 of 3 merged give the unsharded table, byte for byte (CSV and Markdown);
- deleting one run's result and rerunning reruns that run only, and the table is unchanged;
- the shipped sweeps/paper.json is the embedded grid, and sweeps/paper_navigation.json's
  perfect-navigation runs are the same runs (reused by hash); its sensors runs run;
- bad sweep files (unknown JSON path, empty axis, non-finite value, a value the scenario
  refuses, a bad --shard, nesting too deep, an index past an array's end, too many runs) are
  refused with exit status 3 and a message naming the path;
- plot_sweep.py draws the figure from the table;
- kernel paths: each run records its kernel; a bad KELP_KERNEL is refused (exit 3, named);
  merging shards run on different kernel paths warns (stderr and table.md); a sweep with
  "deterministic": true gives the same table and summaries, bit for bit, whatever kernel path
  each shard's process is forced to (KELP_KERNEL), as shards on different CPUs would.
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


def run(*args, env=None):
    full_env = dict(os.environ)
    full_env.pop("KELP_KERNEL", None)
    full_env.update(env or {})
    p = subprocess.run(list(args), capture_output=True, text=True, env=full_env)
    return p.returncode, p.stdout, p.stderr


def summaries(directory):
    """Run hash -> summary without the wall-clock fields."""
    out = {}
    runs = os.path.join(directory, "runs")
    for name in sorted(os.listdir(runs)):
        with open(os.path.join(runs, name)) as f:
            s = json.load(f)["summary"]
        s.pop("wall_s", None)
        s.pop("realtime_factor", None)
        out[name] = s
    return out


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
    check("warning" not in err, "a merge of shards on one kernel path warned: " + err)
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

    # The shipped sweep files: sweeps/paper.json is the embedded grid, and
    # sweeps/paper_navigation.json is that grid times navigation "perfect" / "sensors" whose
    # perfect half is the same runs (same hashes), so it reuses the embedded grid's results. One
    # run of each (300 s) suffices: run 0 of each file is the grid's first point, seed 1.
    sweeps = os.path.dirname(os.path.abspath(small))
    shipped = os.path.join(work, "shipped")
    code, out, err = run(program, "--out", shipped, "--shard", "0/60", "--quiet")
    check(code == 0 and "1 ran, 0 reused" in out, "embedded grid, run 0: " + out + err)
    code, out, err = run(program, "--sweep", os.path.join(sweeps, "paper.json"), "--out", shipped,
                         "--shard", "0/60", "--quiet")
    check(code == 0 and "0 ran, 1 reused" in out,
          "sweeps/paper.json's run 0 is not the embedded grid's: " + out + err)
    nav = os.path.join(sweeps, "paper_navigation.json")
    code, out, err = run(program, "--sweep", nav, "--out", shipped, "--shard", "0/120", "--quiet")
    check(code == 0 and "0 ran, 1 reused" in out,
          "paper_navigation.json's perfect-navigation run 0 is not the embedded grid's: " + out +
          err)
    # Run 5: the same point with navigation from sensors (the last axis varies fastest).
    code, out, err = run(program, "--sweep", nav, "--out", shipped, "--shard", "5/120", "--quiet")
    check(code == 0 and "1 ran, 0 reused" in out, "paper_navigation.json run 5: " + out + err)
    modes = []
    for name in os.listdir(os.path.join(shipped, "runs")):
        with open(os.path.join(shipped, "runs", name)) as f:
            modes.append(json.load(f)["summary"].get("navigation", {}).get("mode", "perfect"))
    modes.sort()
    check(modes == ["perfect", "sensors"], "navigation modes of the shipped runs: %s" % modes)

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
        ("bad deterministic", {"deterministic": "yes"}, "/deterministic"),
        ("deterministic with a wide kernel",
         {"deterministic": True, "base": dict(base.get("base", {}), kernel="avx2")},
         "/deterministic"),
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

    kernel_checks(program, small, work, base)

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


def kernel_checks(program, small, work, base):
    # Every run records the kernel path it took (the widest here, nothing forced).
    for s in summaries(os.path.join(work, "full")).values():
        check(s.get("kernel") in ("portable", "avx2", "avx512"), "a run recorded no kernel")
        check(len(s.get("math_library", "")) == 16, "a run recorded no math library fingerprint")

    # A bad KELP_KERNEL is refused once, naming the variable.
    for bad in ("bogus", "AVX2"):
        code, out, err = run(program, "--sweep", small, "--out", os.path.join(work, "bad"),
                             "--no-plot", "--quiet", env={"KELP_KERNEL": bad})
        check(code == 3 and ("KELP_KERNEL=" + bad) in err,
              "KELP_KERNEL=%s: exit %d, %r" % (bad, code, err.strip()))

    # The paths this CPU runs: a path it lacks is refused with exit 3, never run.
    paths = ["portable"]
    for k in ("avx2", "avx512"):
        code, out, err = run(program, "--sweep", small, "--out", os.path.join(work, "probe-" + k),
                             "--no-plot", "--quiet", "--shard", "0/8", env={"KELP_KERNEL": k})
        if code == 0:
            paths.append(k)
        else:
            check(code == 3 and "cannot be used" in err, "KELP_KERNEL=%s: %r" % (k, err))
            print("skipped %s: this CPU lacks it" % k)
    print("kernel paths on this CPU: " + ", ".join(paths))

    # Shards on different kernel paths (as on different CPUs): the merge warns.
    if len(paths) < 2:
        print("skipped the mixed-kernel merge: this CPU runs only the portable path")
    else:
        mixed = []
        for i in range(3):
            d = os.path.join(work, "mixed-%d" % i)
            k = paths[0] if i == 0 else paths[-1]
            code, out, err = run(program, "--sweep", small, "--out", d, "--shard", "%d/3" % i,
                                 "--quiet", "--jobs", "1", env={"KELP_KERNEL": k})
            check(code == 0, "mixed shard %d failed: %s" % (i, err))
            check(all(s["kernel"] == k for s in summaries(d).values()),
                  "shard %d did not record kernel %s" % (i, k))
            mixed.append(d)
        out_dir = os.path.join(work, "mixed-merged")
        code, out, err = run(program, "merge", *mixed, "--out", out_dir, "--no-plot")
        print(err)
        check(code == 0, "the mixed merge failed: " + err)
        check("warning: the runs were computed on different instruction paths" in err,
              "the mixed merge did not warn: " + err)
        check(paths[0] + " kernel" in err and paths[-1] + " kernel" in err and mixed[0] in err,
              "the warning does not name the kernels and shards: " + err)
        md = read(os.path.join(out_dir, "table.md")).decode()
        check("different instruction paths" in md, "the merged table.md has no warning")

    # A deterministic sweep: each shard's process forced to another path, the same numbers.
    det_file = os.path.join(work, "deterministic.json")
    with open(det_file, "w") as fh:
        json.dump(dict(base, deterministic=True), fh)
    ref = os.path.join(work, "det-full")
    code, out, err = run(program, "--sweep", det_file, "--out", ref, "--no-plot", "--quiet",
                         env={"KELP_KERNEL": paths[-1]})
    check(code == 0, "the deterministic sweep failed: " + err)
    reference = summaries(ref)
    check(all(s["kernel"] == "portable" for s in reference.values()),
          "a deterministic run did not take the portable path")
    shards = []
    for i in range(3):
        d = os.path.join(work, "det-%d" % i)
        code, out, err = run(program, "--sweep", det_file, "--out", d, "--shard", "%d/3" % i,
                             "--quiet", "--jobs", "1", env={"KELP_KERNEL": paths[i % len(paths)]})
        check(code == 0, "deterministic shard %d failed: %s" % (i, err))
        shards.append(d)
    merged = os.path.join(work, "det-merged")
    code, out, err = run(program, "merge", *shards, "--out", merged, "--no-plot")
    check(code == 0 and "warning" not in err, "the deterministic merge warned or failed: " + err)
    check(read(os.path.join(merged, "table.csv")) == read(os.path.join(ref, "table.csv")),
          "the deterministic shards' table differs from the unsharded one")
    check(summaries(merged) == reference,
          "the deterministic shards' summaries differ from the unsharded ones")


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:4]))
