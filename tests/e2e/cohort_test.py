#!/usr/bin/env python3
"""A cohort end to end: created from a patients file, run, worked by an
operator, its coordinator killed, run again, collected.

Two synthetic patients (the fixture's patient 1 and one made here) through
tests/e2e/cohort_workflow.yaml (landmarks, scaling, outline fitting):
  1. `cohort create`: the atlas is stored once under the root (its shared
     store's file has a link per study), every study its own database.
  2. `cohort run -j 2`: both studies stop at the landmark station (exit 3);
     `cohort status --json` says so, with both tasks open for any operator.
  3. A scripted operator places the landmarks (`mmm patient clicks`, as
     `make demo` does) without continuing the runs.
  4. `cohort run -j 2` is killed with SIGKILL while a node runs; its
     `mmm run` children die with it (none left after 5 s).
  5. `cohort run -j 2` again: both studies done. Nothing that had finished
     before the kill ran again (one 'done' execution per cache key), and
     what was killed is recorded as interrupted and ran again.
  6. `mmm gc ROOT --apply` removes only blobs no study's database mentions
     (what the kill left) and every study stays whole: a further run
     executes nothing.
  7. `mmm cohort report ROOT`: both studies done, their contour residuals,
     the operator's landmark errors.

Usage: cohort_test.py --mmm MMM --source REPO --atlas ATLAS --patient PATIENT --work DIR
"""

import argparse
import csv
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def run(args, log, expect=(0,)):
    result = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    log.write(f"$ {' '.join(str(a) for a in args)}\n{result.stdout}{result.stderr}\n")
    log.flush()
    if result.returncode not in expect:
        fail(f"{' '.join(str(a) for a in args)} exited {result.returncode}:\n"
             f"{result.stdout}\n{result.stderr}")
    return result


def status(args, root, log):
    return json.loads(run([args.mmm, "cohort", "status", root, "--json"], log).stdout)


def executions(study):
    db = sqlite3.connect(f"file:{study / 'study.db'}?mode=ro", uri=True)
    rows = db.execute("SELECT node, cache_key, status FROM executions").fetchall()
    db.close()
    return rows


def blob_files(root):
    """Every artifact file under the root: the studies' and the shared store's."""
    found = set()
    for store in [root / ".mmm-store", *(d / "artifacts" for d in root.iterdir() if d.is_dir())]:
        if store.is_dir():
            found.update(p for p in store.glob("??/*") if len(p.parent.name + p.name) == 64)
    return found


def database_text(study):
    """The whole study database as SQL text (every table, every value)."""
    db = sqlite3.connect(f"file:{study / 'study.db'}?mode=ro", uri=True)
    text = "\n".join(db.iterdump())
    db.close()
    return text


def live_runs(root):
    """Processes running `mmm run` on a study under root."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmdline = (Path("/proc") / pid / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if len(cmdline) > 2 and cmdline[1] == b"run" and str(root).encode() in cmdline[2]:
            found.append(int(pid))
    return found


def main():
    parser = argparse.ArgumentParser()
    for name in ("mmm", "source", "atlas", "patient", "work"):
        parser.add_argument(f"--{name}", type=Path, required=True)
    args = parser.parse_args()
    for name in ("mmm", "source", "atlas", "patient", "work"):
        setattr(args, name, getattr(args, name).resolve())
    if args.work.exists():
        shutil.rmtree(args.work)
    args.work.mkdir(parents=True)
    log = open(args.work / "log.txt", "w")
    root = args.work / "cohort"

    patients = {"p1": args.patient, "p2": args.work / "patient_2"}
    run([args.mmm, "patient", "synth", "--atlas", args.atlas, "--seed", "2", "-o",
         patients["p2"]], log)
    with open(args.work / "patients.csv", "w", newline="") as out:
        writer = csv.writer(out)
        writer.writerow(["id", "patient", "calibration", "frontal", "lateral"])
        for pid, folder in patients.items():
            r = folder / "radiographs"
            writer.writerow([pid, pid.upper(), r / "views.json", r / "frontal.png",
                             r / "lateral.png"])

    # 1. Created, the atlas stored once.
    run([args.mmm, "cohort", "create", root, "--workflow",
         args.source / "tests/e2e/cohort_workflow.yaml", "--patients",
         args.work / "patients.csv", "--input", f"atlas={args.atlas}"], log)
    db = sqlite3.connect(f"file:{root / 'p1' / 'study.db'}?mode=ro", uri=True)
    atlas_hash = db.execute("SELECT hash FROM inputs WHERE name = 'atlas'").fetchone()[0]
    db.close()
    shared = root / ".mmm-store" / atlas_hash[:2] / atlas_hash[2:]
    if not shared.is_file() or os.stat(shared).st_nlink != 3:
        fail(f"the atlas is not shared by the two studies: {shared}")
    for pid in patients:
        if os.stat(root / pid / "artifacts" / atlas_hash[:2] / atlas_hash[2:]).st_ino != \
                os.stat(shared).st_ino:
            fail(f"{pid}'s atlas is a copy, not the shared file")
    print(f"created: the atlas ({os.stat(shared).st_size >> 20} MB) stored once for 2 studies")

    # 2. Both wait for the landmark station.
    run([args.mmm, "cohort", "run", root, "-j", "2"], log, expect=(3,))
    state = status(args, root, log)
    if state["counts"] != {"waiting": 2} or state["waiting_on"] != {"": 2}:
        fail(f"after the first run: {state['counts']}, waiting on {state['waiting_on']}")

    # 3. The scripted operator.
    token = args.work / "bot.token"
    with open(token, "w") as out:
        subprocess.run([str(args.mmm), "operator", "add", "bot", "--root", str(root)],
                       stdout=out, check=True)
    os.chmod(token, 0o600)
    tasks = json.loads(run([args.mmm, "worklist", "--root", root, "--json"], log).stdout)
    for entry in tasks:
        pid = entry["study"]
        clicks = args.work / f"{pid}_clicks.json"
        run([args.mmm, "patient", "clicks", patients[pid], "-o", clicks, "--seed", "1"], log)
        run([args.mmm, "task", "claim", entry["task"], "--root", root, "--token-file", token], log)
        run([args.mmm, "task", "submit", entry["task"], "--root", root, "--token-file", token,
             "--file", clicks, "--no-run"], log)

    # 4. The coordinator killed while a node runs.
    coordinator = subprocess.Popen([str(args.mmm), "cohort", "run", str(root), "-j", "2"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 300
    while time.time() < deadline:
        running = [e for pid in patients for e in executions(root / pid) if e[2] == "running"]
        if any(node == "outlines" for node, _, _ in running):
            break
        time.sleep(0.2)
    else:
        fail("no outline fit started within 300 s")
    time.sleep(1.0)
    coordinator.send_signal(signal.SIGKILL)
    coordinator.wait()
    deadline = time.time() + 5
    while live_runs(root) and time.time() < deadline:
        time.sleep(0.1)
    if live_runs(root):
        fail(f"runs outlived their killed coordinator: {live_runs(root)}")
    before = {pid: executions(root / pid) for pid in patients}

    # 5. Run again: done, nothing finished redone.
    run([args.mmm, "cohort", "run", root, "-j", "2"], log)
    state = status(args, root, log)
    if state["counts"] != {"done": 2}:
        fail(f"after resuming: {state['counts']}")
    interrupted = 0
    for pid in patients:
        after = executions(root / pid)
        done_keys = [key for _, key, st in after if st == "done"]
        if len(done_keys) != len(set(done_keys)):
            fail(f"{pid}: a node that had finished ran again")
        finished_before = {key for _, key, st in before[pid] if st == "done"}
        if not finished_before <= set(done_keys):
            fail(f"{pid}: a result finished before the kill is gone")
        interrupted += sum(1 for _, _, st in after if st == "interrupted")
        if not (root / pid / "outputs").is_dir():
            fail(f"{pid}: no outputs")
    if interrupted == 0:
        fail("the kill interrupted no execution (the test did not test a kill)")

    # 6. Collected. What gc finds can only be what the kill left: outputs a
    # node had stored when the kill came before its record was committed,
    # which its re-run wrote again with other bytes (a fit's time, say).
    # Whatever it removes must be mentioned in no study's database, and every
    # study must stay whole: a further run finds nothing to do.
    blobs_before = blob_files(root)
    report = json.loads(run([args.mmm, "gc", root, "--json", "--grace-minutes", "0",
                             "--apply"], log).stdout)
    removed = blobs_before - blob_files(root)
    if len(removed) != report["study_blobs"] + report["shared_blobs"]:
        fail(f"gc reported {report} but removed {len(removed)} files")
    for pid in patients:
        mentioned = database_text(root / pid)
        for path in removed:
            if path.parent.name + path.name in mentioned:
                fail(f"gc removed {path}, which {pid}'s database mentions")
    before_rerun = {pid: executions(root / pid) for pid in patients}
    run([args.mmm, "cohort", "run", root, "-j", "2"], log)
    for pid in patients:
        if executions(root / pid) != before_rerun[pid]:
            fail(f"{pid}: a run after gc executed nodes again (a blob it needed is gone)")
    # 7. The cohort's report.
    run([args.mmm, "cohort", "report", root], log)
    page = (root / "cohort_report" / "index.html").read_text()
    for expected in ('<h2 id="figures">', "mean contour residual", "2 of 2 studies done",
                     "<td>bot</td><td>2</td>"):
        if expected not in page:
            fail(f"the cohort report lacks {expected!r}")

    print(f"cohort: 2 studies done after a SIGKILL of the coordinator ({interrupted} interrupted "
          f"execution(s) re-run, nothing finished redone); "
          f"{report['kept_bytes'] >> 20} MB under the root, {len(removed)} unreferenced "
          f"file(s) collected")


if __name__ == "__main__":
    main()
