#!/usr/bin/env python3
"""Which .cpp files clang-tidy must look at, against the lint baseline.

  .ci/lint_affected.py BASELINE          prints the .cpp files to lint, or the
                                         single line ALL when everything must be
  .ci/lint_affected.py --record BASELINE writes BASELINE from the current tree

BASELINE lists "<git blob id> <path>" for every tracked .h/.cpp and for the
files that decide what clang-tidy reports (.clang-tidy, the compile flags), as
they were when the whole tree last passed `.ci/lint --all`. It needs no git
history, so a shallow clone reads it as well as a full one.

A file must be linted when its blob differs from the baseline's (or it is new,
or modified in the working tree), and so must every .cpp that includes such a
header of ours, directly or through a chain of our headers (includes are
written from the repository root, e.g. #include "core/mesh/mesh.h").
Everything must be linted when a settings file changed or the baseline is
missing."""
import os
import re
import subprocess
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)
SETTINGS = [".clang-tidy", "cmake/MmmTargets.cmake", "CMakeLists.txt"]


def git(*args):
    return subprocess.run(["git", *args], check=True, capture_output=True, text=True).stdout


def current_blobs():
    """path -> blob id of the index, for sources and settings."""
    blobs = {}
    for line in git("ls-files", "-s", "--", "*.h", "*.cpp", *SETTINGS).splitlines():
        meta, path = line.split("\t", 1)
        blobs[path] = meta.split()[1]
    return blobs


def dirty_paths():
    """Modified (vs the index or HEAD) and untracked files of the working tree."""
    paths = set(git("diff", "--name-only", "HEAD").split())
    paths |= set(git("ls-files", "--others", "--exclude-standard").split())
    return paths


def record(baseline):
    with open(baseline, "w", encoding="utf-8") as f:
        f.write("# blob path: the tree that last passed `.ci/lint --all` (see .ci/lint)\n")
        for path, blob in sorted(current_blobs().items()):
            f.write(f"{blob} {path}\n")


def read_baseline(baseline):
    recorded = {}
    try:
        with open(baseline, encoding="utf-8") as f:
            for line in f:
                if line.startswith("#") or not line.strip():
                    continue
                blob, path = line.rstrip("\n").split(" ", 1)
                recorded[path] = blob
    except FileNotFoundError:
        return None
    return recorded


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--record":
        record(sys.argv[2])
        return
    recorded = read_baseline(sys.argv[1])
    if not recorded:
        print("ALL")
        return
    blobs = current_blobs()
    dirty = dirty_paths()
    changed = {p for p, b in blobs.items() if recorded.get(p) != b} | dirty
    if any(s in changed for s in SETTINGS):
        print("ALL")
        return
    sources = [p for p in blobs if p.endswith((".h", ".cpp"))]
    sources += [p for p in dirty if p.endswith((".h", ".cpp")) and p not in blobs]
    includes = {}
    for path in sources:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                includes[path] = set(INCLUDE.findall(f.read()))
        except FileNotFoundError:  # deleted in the working tree
            includes[path] = set()
    affected = {p for p in changed if p.endswith((".h", ".cpp"))}
    grew = True
    while grew:
        grew = False
        for path in sources:
            if path not in affected and includes[path] & affected:
                affected.add(path)
                grew = True
    for path in sorted(p for p in affected if p.endswith(".cpp") and os.path.exists(p)):
        print(path)


if __name__ == "__main__":
    main()
