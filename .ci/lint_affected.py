#!/usr/bin/env python3
"""Reads changed paths (one per line) on stdin; prints the .cpp files of the
repository that clang-tidy must look at again: the changed .cpp files that
still exist, and every .cpp that includes a changed header of ours, directly
or through a chain of our headers (includes are written from the repository
root, e.g. #include "core/mesh/mesh.h")."""
import re
import subprocess
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def tracked_sources():
    out = subprocess.run(["git", "ls-files", "*.h", "*.cpp"], check=True,
                         capture_output=True, text=True).stdout
    return [p for p in out.splitlines() if p]


def main():
    changed = {line.strip() for line in sys.stdin if line.strip()}
    sources = tracked_sources()
    includes = {}
    for path in sources:
        with open(path, encoding="utf-8", errors="replace") as f:
            includes[path] = set(INCLUDE.findall(f.read()))
    dirty = {p for p in changed if p.endswith((".h", ".cpp", ".inc", ".in"))}
    # Fixed point: a file is affected when it includes an affected header.
    grew = True
    while grew:
        grew = False
        for path in sources:
            if path not in dirty and includes[path] & dirty:
                dirty.add(path)
                grew = True
    for path in sorted(p for p in dirty if p.endswith(".cpp") and p in includes):
        print(path)


if __name__ == "__main__":
    main()
