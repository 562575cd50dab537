#!/usr/bin/env python3
"""Which .cpp files clang-tidy must look at, against the lint baseline.

  .ci/lint_affected.py BASELINE          prints the .cpp files to lint
  .ci/lint_affected.py --record BASELINE writes BASELINE from the current tree

BASELINE lists "<git blob id> <path>" for every tracked .h/.cpp and for the
files that decide what clang-tidy reports (.clang-tidy, the compile flags), as
they were when the whole tree last passed `.ci/lint --all`. It needs no git
history, so a shallow clone reads it as well as a full one.

A .cpp must be linted when its blob differs from the baseline's (or it is new,
or modified in the working tree). A changed header is linted through one
translation unit that includes it (clang-tidy reports a header's findings from
any includer, see HeaderFilterRegex): its own .cpp when it has one, otherwise
the first .cpp that includes it, directly or through a chain of our headers
(includes are written from the repository root, e.g.
#include "core/mesh/mesh.h"). So the set grows with what changed, never with
how widely a header is used: a change to core/errors.h lints one file, not
every file that includes it.

A changed settings file (.clang-tidy, the compile flags) is reported on
stderr: it can change findings anywhere, which only `.ci/lint --all`, run by
hand, checks; CI never lints the whole tree. A missing baseline prints ALL."""
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


def includers(sources):
    """path -> set of our headers it includes directly."""
    found = {}
    for path in sources:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                found[path] = set(INCLUDE.findall(f.read()))
        except FileNotFoundError:  # deleted in the working tree
            found[path] = set()
    return found


def translation_unit_for(header, includes):
    """The .cpp through which clang-tidy sees a changed header, or None."""
    own = os.path.splitext(header)[0] + ".cpp"
    if own in includes and header in includes[own] and os.path.exists(own):
        return own
    reached = {header}
    grew = True
    while grew:  # headers that include the header, directly or through others
        grew = False
        for path, included in includes.items():
            if path.endswith(".h") and path not in reached and included & reached:
                reached.add(path)
                grew = True
    for path in sorted(includes):
        if path.endswith(".cpp") and includes[path] & reached and os.path.exists(path):
            return path
    return None


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
    settings = sorted(s for s in SETTINGS if s in changed)
    if settings:
        print(f"lint: {', '.join(settings)} changed since the baseline: findings may change in "
              "files not linted here; run `.ci/lint --all` by hand and commit the baseline it "
              "records", file=sys.stderr)
    sources = [p for p in blobs if p.endswith((".h", ".cpp"))]
    sources += [p for p in dirty if p.endswith((".h", ".cpp")) and p not in blobs]
    includes = includers(sources)
    affected = {p for p in changed if p.endswith(".cpp") and os.path.exists(p)}
    for header in sorted(p for p in changed if p.endswith(".h") and os.path.exists(p)):
        unit = translation_unit_for(header, includes)
        if unit:
            affected.add(unit)
        else:
            print(f"lint: no .cpp includes {header}; clang-tidy does not see it", file=sys.stderr)
    for path in sorted(affected):
        print(path)


if __name__ == "__main__":
    main()
