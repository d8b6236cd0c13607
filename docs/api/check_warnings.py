#!/usr/bin/env python3
"""Doxygen's warnings over include/kelp, counted per header (the `docs` target runs it).

Usage: check_warnings.py LOG INCLUDE_DIR

LOG is Doxygen's WARN_LOGFILE. Each warning (a first line "file:line: warning: ...", then its
continuation lines) is attributed to its header, relative to INCLUDE_DIR (kelp/tether/winch.hpp);
a warning Doxygen gives without a file ("<name>:1: ...", a member documented apart from its
declaration) is attributed to the header that declares the member. Any warning fails the check:
every public type, function and parameter is documented. The warnings are printed per header.
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


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: check_warnings.py LOG INCLUDE_DIR")
    log, include_dir = sys.argv[1:]
    warnings = read_warnings(log, include_dir)
    total = sum(len(v) for v in warnings.values())
    if not total:
        print("check_warnings: no Doxygen warning")
        return 0
    print("check_warnings: Doxygen warnings per header:")
    for k in sorted(warnings):
        print("  %4d  %s" % (len(warnings[k]), k))
    for k in sorted(warnings):
        print("\ncheck_warnings: %s:" % k)
        for w in warnings[k]:
            print("  " + "\n    ".join(w))
    print("\ncheck_warnings: FAILED: %d Doxygen warnings in %d headers (document every public type, "
          "function and parameter: units, frames, what it throws)" % (total, len(warnings)))
    return 1


if __name__ == "__main__":
    sys.exit(main())
