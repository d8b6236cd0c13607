#!/usr/bin/env python3
"""Doxygen's warnings over include/kelp, counted per header (the `docs` target runs it).

Usage: check_warnings.py LOG INCLUDE_DIR BASELINE [--update]

LOG is Doxygen's WARN_LOGFILE. Each warning (a first line "file:line: warning: ...", then its
continuation lines) is attributed to its header, relative to INCLUDE_DIR (kelp/tether/winch.hpp);
a warning Doxygen gives without a file ("<name>:1: ...", a member documented apart from its
declaration) is attributed to "<name>".

BASELINE lists, one "count header" a line, the warnings each header still had when the check was
introduced: the API reference is being completed header by header, and the goal is an empty
file. The check fails when any header has more warnings than its baseline (a header not listed
has a baseline of 0: a new header must be fully documented), printing every warning of those
headers; it reports the headers now below their baseline, and --update rewrites BASELINE with
today's counts (run it after documenting a header, so that its count cannot rise again).

Always prints a per-header table of today's counts (the first column), so that one run says
what remains.
"""
import collections
import os
import re
import sys

FIRST = re.compile(r"^(?P<file>.+?):(?P<line>\d+): (?P<kind>warning|error): (?P<text>.*)$")


def locate(name, member, include_dir, cache={}):
    """The header that declares `member` (kelp::tether::step: a function `step` in a header whose
    directory is a namespace of the qualified name, else the first header that declares it)."""
    short = member.split("::")[-1]
    if "index" not in cache:
        # Every identifier followed by "(" in every header: name -> headers, built once.
        index = {}
        for d, _, files in os.walk(include_dir):
            for fn in sorted(files):
                if fn.endswith(".hpp"):
                    p = os.path.join(d, fn)
                    rel = os.path.relpath(p, include_dir)
                    with open(p, encoding="utf-8", errors="replace") as fh:
                        for ident in set(re.findall(r"\b([A-Za-z_~]\w*)\s*\(", fh.read())):
                            index.setdefault(ident, []).append(rel)
        cache["index"] = {k: sorted(v) for k, v in index.items()}
    parts = member.split("::")[1:-1]
    if "classes" not in cache:
        # Every class and struct defined in every header: name -> headers.
        classes = {}
        for d, _, files in os.walk(include_dir):
            for fn in sorted(files):
                if fn.endswith(".hpp"):
                    p = os.path.join(d, fn)
                    with open(p, encoding="utf-8", errors="replace") as fh:
                        for c in set(re.findall(r"\b(?:class|struct)\s+(?:KELP_SIM_API\s+)?(\w+)\s*(?:final\s*)?[:{]",
                                                fh.read())):
                            classes.setdefault(c, []).append(os.path.relpath(p, include_dir))
        cache["classes"] = classes
    # A member of a class: the header that defines the class.
    if parts and parts[-1] in cache["classes"]:
        owners = sorted(cache["classes"][parts[-1]])
        for rel in owners:
            if any("/%s/" % p in "/" + rel for p in parts[:-1]):
                return rel
        return owners[0]
    found = cache["index"].get(short, [])
    for rel in found:
        if any("/%s/" % p in "/" + rel for p in parts):
            return rel
    return found[0] if found else name


def read_warnings(log, include_dir):
    include_dir = os.path.realpath(include_dir)
    warnings = collections.OrderedDict()
    current = None
    with open(log, encoding="utf-8", errors="replace") as f:
        for raw in f:
            line = raw.rstrip("\n")
            m = FIRST.match(line)
            if m:
                path = m.group("file")
                if path.startswith("<"):
                    member = re.search(r"member (\S+)", m.group("text"))
                    key = locate(path, member.group(1), include_dir) if member else path
                else:
                    real = os.path.realpath(path)
                    key = (os.path.relpath(real, include_dir)
                           if real.startswith(include_dir + os.sep) else path)
                current = [line]
                warnings.setdefault(key, []).append(current)
            elif current is not None and line.strip():
                current.append(line)
            elif line.strip():
                warnings.setdefault("(unattributed)", []).append([line])
    return warnings


def read_baseline(path):
    base = {}
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            for line in f:
                line = line.strip()
                if line and not line.startswith("#"):
                    count, name = line.split(None, 1)
                    base[name] = int(count)
    return base


def write_baseline(path, counts):
    with open(path, "w", encoding="utf-8") as f:
        f.write("# Doxygen warnings per public header still to be fixed (docs/api/check_warnings.py):\n"
                "# a header may not have more; the goal is an empty file. Lower it with\n"
                "# `cmake --build <build> --target docs_update_baseline`.\n")
        for name in sorted(counts):
            if counts[name]:
                f.write("%d %s\n" % (counts[name], name))


def main():
    args = [a for a in sys.argv[1:] if a != "--update"]
    update = "--update" in sys.argv[1:]
    if len(args) != 3:
        sys.exit("usage: check_warnings.py LOG INCLUDE_DIR BASELINE [--update]")
    log, include_dir, baseline_path = args
    warnings = read_warnings(log, include_dir)
    counts = {k: len(v) for k, v in warnings.items()}
    total = sum(counts.values())
    if update:
        write_baseline(baseline_path, counts)
        print("check_warnings: %s rewritten: %d warnings in %d headers"
              % (baseline_path, total, len(counts)))
        return 0
    base = read_baseline(baseline_path)
    worse = sorted(k for k in counts if counts[k] > base.get(k, 0))
    better = sorted(k for k in base if counts.get(k, 0) < base[k])
    print("check_warnings: Doxygen warnings per header (today / baseline):")
    for k in sorted(set(counts) | set(base)):
        flag = " <- MORE THAN ITS BASELINE" if k in worse else (" (below its baseline)" if k in better else "")
        print("  %4d / %4d  %s%s" % (counts.get(k, 0), base.get(k, 0), k, flag))
    print("check_warnings: %d warnings in %d headers (baseline %d)"
          % (total, len(counts), sum(base.values())))
    for k in worse:
        print("\ncheck_warnings: %s: %d warnings, baseline %d:" % (k, counts[k], base.get(k, 0)))
        for w in warnings[k]:
            print("  " + "\n    ".join(w))
    if better:
        print("\ncheck_warnings: below their baseline (lower it: the docs_update_baseline target): "
              + ", ".join(better))
    if worse:
        print("\ncheck_warnings: FAILED: %d headers have more Doxygen warnings than their baseline "
              "(document every public type, function and parameter: units, frames, what it throws)"
              % len(worse))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
