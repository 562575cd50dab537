#!/usr/bin/env python3
"""End to end: the default study as `make demo` runs it (cmake/demo.sh).

1. Restart: one demo run left alone (A); another (B) killed with SIGKILL,
   the whole process group, at several points (while the patient is being
   made, while scaling, wrapping and fibres run), then run again until it
   finishes. B's outputs must equal A's: every file byte for byte, except
   the measured times (JSON keys and CSV columns of seconds and
   milliseconds, and the time panel of wrapping_plot.svg).
2. Correction: in B, one landmark (the patella centre) is corrected through
   the worklist (mmm task submit --reason). Scaling and every node after it
   run again; the radiographs node does not. The report's audit shows both
   submissions and the corrected landmark's reason.

The study walks 0.5-0.8 s of the trial instead of 0.5-2.5 s (same workflow
and code, a sixth of the frames) to fit the CI budget.

  default_study_test.py --mmm BIN --source DIR --data DIR --atlas DIR
                        --patient DIR --work DIR
"""

import argparse
import csv
import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

SETTINGS = ["motion.end_time=0.8"]
TIMING_KEY = re.compile(r"(second|_s$|(^|_)ms($|_)|^time$)")
TIMING_COLUMN = re.compile(r"(^ms$|second)")
NOT_COMPARED = {"wrapping_plot.svg"}  # its time panel is measured time


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    sys.exit(1)


def demo_command(args, demo):
    return ["bash", str(args.source / "cmake/demo.sh"), str(args.mmm), str(args.atlas),
            str(args.data), str(demo), "2", "0"] + SETTINGS


def run_demo(args, demo, log):
    with open(log, "a") as out:
        code = subprocess.call(demo_command(args, demo), cwd=args.source, stdout=out,
                               stderr=subprocess.STDOUT)
    if code != 0:
        fail(f"demo run in {demo} exited {code}; see {log}")


def in_group(pid, group):
    try:
        return os.getpgid(pid) == group
    except (ProcessLookupError, TypeError):
        return False


def node_running(args, study, node, group):
    """Whether `node` has an execution running in the process group `group`
    (a killed run's record says 'running' until the next run marks it
    interrupted)."""
    if not (study / "study.db").exists():
        return False
    status = subprocess.run([str(args.mmm), "status", str(study), "--json"], capture_output=True,
                            text=True)
    if status.returncode != 0:
        return False
    for entry in json.loads(status.stdout).get("nodes", []):
        last = entry.get("last_execution") or {}
        if (entry.get("id") == node and last.get("status") == "running"
                and in_group(last.get("pid"), group)):
            return True
    return False


def kill_demo_when(args, demo, log, ready, after_s, label):
    """Starts the demo in its own process group, waits until ready(), then
    after after_s seconds kills the whole group with SIGKILL."""
    with open(log, "a") as out:
        out.write(f"\n=== run killed {label} ===\n")
        out.flush()
        process = subprocess.Popen(demo_command(args, demo), cwd=args.source, stdout=out,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.monotonic() + 900
        while not ready(process.pid):
            if process.poll() is not None:
                fail(f"the demo ended (exit {process.returncode}) before it was {label}; see {log}")
            if time.monotonic() > deadline:
                os.killpg(process.pid, signal.SIGKILL)
                fail(f"the demo was never {label}")
            time.sleep(0.2)
        time.sleep(after_s)
        if process.poll() is not None:
            fail(f"the demo finished before the kill {label}: choose a later point")
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        # Every process of the group gone (and with it the study lock).
        while True:
            try:
                os.killpg(process.pid, 0)
            except ProcessLookupError:
                break
            time.sleep(0.05)
    print(f"killed {label}", flush=True)


def without_timing(value):
    if isinstance(value, dict):
        return {k: without_timing(v) for k, v in value.items() if not TIMING_KEY.search(k)}
    if isinstance(value, list):
        return [without_timing(v) for v in value]
    return value


def comparable(path):
    data = path.read_bytes()
    if path.suffix == ".json":
        return json.dumps(without_timing(json.loads(data)), sort_keys=True).encode()
    if path.suffix == ".csv":
        rows = list(csv.reader(io.StringIO(data.decode())))
        keep = [i for i, name in enumerate(rows[0]) if not TIMING_COLUMN.search(name)]
        return "\n".join(",".join(row[i] for i in keep) for row in rows).encode()
    return data


def compare_outputs(a, b):
    files_a = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    files_b = sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    if files_a != files_b:
        fail(f"different output files: only in A {sorted(set(files_a) - set(files_b))}, "
             f"only in B {sorted(set(files_b) - set(files_a))}")
    different = [str(f) for f in files_a
                 if f.name not in NOT_COMPARED and comparable(a / f) != comparable(b / f)]
    if different:
        fail(f"outputs differ after the interrupted runs: {different}")
    return len(files_a)


def status(args, study):
    out = subprocess.run([str(args.mmm), "status", str(study), "--json"], capture_output=True,
                         text=True, check=True).stdout
    return {n["id"]: n for n in json.loads(out)["nodes"]}


def execution_ids(nodes):
    return {node: (entry.get("result") or {}).get("id") for node, entry in nodes.items()}


def correct_patella(args, demo):
    root = demo / "studies"
    study = root / "patient_1"
    listed = subprocess.run([str(args.mmm), "worklist", "--root", str(root), "--json", "--all"],
                            capture_output=True, text=True)
    if listed.returncode != 0:
        fail("mmm worklist --all: " + listed.stderr)
    tasks = [t for t in json.loads(listed.stdout) if t["node"] == "landmarks"]
    if len(tasks) != 1 or tasks[0]["state"] != "accepted":
        fail(f"expected one accepted landmark task, got {tasks}")
    clicks = json.loads((demo / "scripted_clicks.json").read_text())
    for view in clicks["landmarks"]["patella_centre_r"].values():
        view[1] += 4.0  # 4 px lower in both views (~1.5 mm)
    corrected = demo / "corrected_clicks.json"
    corrected.write_text(json.dumps(clicks))
    before = execution_ids(status(args, study))
    reason = "patella centre placed on the upper pole; moved to the centre"
    submitted = subprocess.run(
        [str(args.mmm), "task", "submit", tasks[0]["task"], "--root", str(root), "--token-file",
         str(demo / "scripted-operator.token"), "--file", str(corrected), "--reason", reason,
         "-j", "2"],
        capture_output=True, text=True)
    if submitted.returncode != 0:
        fail("the correction was refused: " + submitted.stdout + submitted.stderr)
    after = execution_ids(status(args, study))
    rerun = sorted(n for n in before if after[n] != before[n])
    expected = ["fibres", "hulls", "landmarks", "motion", "outlines", "scaled", "wrap"]
    if rerun != expected:
        fail(f"after the correction these nodes have new results: {rerun}; expected {expected}")
    report = subprocess.run([str(args.mmm), "report", str(study)], capture_output=True, text=True)
    if report.returncode != 0:
        fail("mmm report: " + report.stderr)
    html = (study / "report/index.html").read_text()
    submissions = len(re.findall(r"<td>scripted-operator</td><td>submit</td>", html))
    if submissions != 2:
        fail(f"the report's audit shows {submissions} submissions, expected 2")
    if reason not in html:
        fail("the report's audit does not show the correction's reason")
    print(f"correction: new results for {', '.join(rerun)}; radiographs kept; the audit shows "
          "both submissions", flush=True)


def main():
    parser = argparse.ArgumentParser()
    for name in ("mmm", "source", "data", "atlas", "patient", "work"):
        parser.add_argument("--" + name, type=Path, required=True)
    args = parser.parse_args()
    args.mmm = args.mmm.resolve()
    shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True)
    log = args.work / "demo.log"

    # A: left alone (the patient is the fixture's, the same seed as the demo's).
    demo_a = args.work / "a"
    demo_a.mkdir()
    shutil.copytree(args.patient, demo_a / "patient_1")
    run_demo(args, demo_a, log)
    print("A: finished without interruption", flush=True)

    # B: killed at several points, then run until it finishes.
    demo_b = args.work / "b"
    study_b = demo_b / "studies/patient_1"
    kill_demo_when(args, demo_b, log, lambda group: (demo_b / "patient_1").exists(), 2.0,
                   "while making the patient")
    for node, after_s in (("scaled", 0.5), ("wrap", 1.5), ("fibres", 1.0)):
        kill_demo_when(args, demo_b, log,
                       lambda group, n=node: node_running(args, study_b, n, group), after_s,
                       f"while '{node}' ran")
    run_demo(args, demo_b, log)
    files = compare_outputs(demo_a / "studies/patient_1/outputs", study_b / "outputs")
    print(f"restart: {files} output files of the killed-and-resumed study equal the "
          "uninterrupted one's", flush=True)

    correct_patella(args, demo_b)
    print("PASS")


if __name__ == "__main__":
    main()
