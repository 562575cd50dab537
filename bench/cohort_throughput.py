#!/usr/bin/env python3
"""A cohort of synthetic patients through workflows/default.yaml, run here
(`mmm cohort run -j 2`) and as Slurm jobs on a single-node cluster started on
this machine (tests/slurm/local_cluster.sh), with the scripted operator of
`make demo` placing the landmarks in between.

For each executor it prints and writes (JSON) the cohort's wall time (the two
`cohort run` passes; the operator's clicks are timed apart), each patient's
time (the sum of its study's runs), how many node executions ran, and the
difference per node execution between the two executors.

Usage: cohort_throughput.py --mmm MMM --source REPO --atlas ATLAS --data DATA
       --work DIR [--patients 20] [--end-time SECONDS] [--executors local,slurm]
       [--jobs 2] [--out FILE]
"""

import argparse
import csv
import json
import re
import os
import shutil
import sqlite3
import statistics
import subprocess
import sys
import time
from datetime import datetime
from pathlib import Path


def fail(message):
    print(f"cohort_throughput: {message}", file=sys.stderr)
    sys.exit(1)


def run(argv, env=None, expect=(0,)):
    argv = [str(a) for a in argv]
    result = subprocess.run(argv, capture_output=True, text=True, env=env)
    if result.returncode not in expect:
        fail(f"{' '.join(argv)} exited {result.returncode}:\n{result.stdout}\n{result.stderr}")
    return result


def utc_seconds(text):
    return datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


SLURM_LINE = re.compile(r"ran as Slurm job \S+: ([0-9.]+) s on the node, ([0-9.]+) s more in Slurm")


def study_figures(study):
    """(seconds of all its runs, node executions done, Slurm's seconds per
    node execution) from the study's database."""
    db = sqlite3.connect(f"file:{study / 'study.db'}?mode=ro", uri=True)
    seconds = sum(utc_seconds(b) - utc_seconds(a) for a, b in db.execute(
        "SELECT started_at, finished_at FROM runs WHERE finished_at IS NOT NULL"))
    done = db.execute("SELECT COUNT(*) FROM executions WHERE status = 'done'").fetchone()[0]
    in_slurm = [float(m.group(2)) for (message,) in db.execute(
        "SELECT message FROM logs WHERE message LIKE 'ran as Slurm job %'")
        if (m := SLURM_LINE.match(message))]
    db.close()
    return seconds, done, in_slurm


def one_cohort(args, executor, patients_csv, patients, env):
    root = args.work / executor
    run([args.mmm, "cohort", "create", root, "--workflow", args.source / "workflows/default.yaml",
         "--patients", patients_csv, "--input", f"atlas={args.atlas}",
         "--input", f"model={args.data}/gait2392/Pipelines/reference/subject01_simbody.osim",
         "--input", f"trial={args.data}/gait2392/Pipelines/subject01_walk1.trc"], env)
    if args.end_time is not None:
        for pid in patients:
            run([args.mmm, "study", "set", root / pid, f"motion.end_time={args.end_time}"], env)
    flags = ["-j", str(args.jobs)]
    if executor == "slurm":
        flags += ["--executor", "slurm", "--node-jobs", str(args.jobs)]

    start = time.monotonic()
    run([args.mmm, "cohort", "run", root, *flags], env, expect=(3,))
    to_station = time.monotonic() - start

    clicking = time.monotonic()
    token = args.work / f"{executor}.token"
    with open(token, "w") as out:
        subprocess.run([str(args.mmm), "operator", "add", "scripted-operator", "--root",
                        str(root)], stdout=out, stderr=subprocess.DEVNULL, check=True, env=env)
    os.chmod(token, 0o600)
    tasks = json.loads(run([args.mmm, "worklist", "--root", root, "--json"], env).stdout)
    if len(tasks) != len(patients):
        fail(f"{executor}: {len(tasks)} open tasks for {len(patients)} patients")
    for entry in tasks:
        clicks = args.work / f"{entry['study']}_clicks.json"
        run([args.mmm, "patient", "clicks", patients[entry["study"]], "-o", clicks, "--seed", "1"],
            env)
        run([args.mmm, "task", "claim", entry["task"], "--root", root, "--token-file", token], env)
        run([args.mmm, "task", "submit", entry["task"], "--root", root, "--token-file", token,
             "--file", clicks, "--no-run"], env)
    operator = time.monotonic() - clicking

    resumed = time.monotonic()
    run([args.mmm, "cohort", "run", root, *flags], env)
    to_end = time.monotonic() - resumed
    status = json.loads(run([args.mmm, "cohort", "status", root, "--json"], env).stdout)
    if status["counts"] != {"done": len(patients)}:
        fail(f"{executor}: the cohort did not finish: {status['counts']}")

    per_patient, nodes, in_slurm = [], 0, []
    for pid in patients:
        seconds, done, extra = study_figures(root / pid)
        per_patient.append(seconds)
        nodes += done
        in_slurm += extra
    # Every node execution but the manual ones (tasks, not jobs) is a job.
    if executor == "slurm" and not in_slurm:
        fail("no node execution ran as a Slurm job")
    return {"executor": executor, "patients": len(patients), "wall_seconds": to_station + to_end,
            "to_station_seconds": to_station, "to_end_seconds": to_end,
            "operator_seconds": operator, "node_executions": nodes,
            "per_patient_median_seconds": statistics.median(per_patient),
            "per_patient_max_seconds": max(per_patient),
            "per_patient_sum_seconds": sum(per_patient),
            "slurm_jobs": len(in_slurm),
            "slurm_seconds_per_node_median": statistics.median(in_slurm) if in_slurm else None,
            "slurm_seconds_per_node_p90": (statistics.quantiles(in_slurm, n=10)[-1]
                                           if len(in_slurm) > 1 else None)}


def main():
    parser = argparse.ArgumentParser()
    for name in ("mmm", "source", "atlas", "data", "work"):
        parser.add_argument(f"--{name}", type=Path, required=True)
    parser.add_argument("--patients", type=int, default=20)
    parser.add_argument("--end-time", type=float, default=None,
                        help="the walk's end (s); default: the workflow's (the whole walk)")
    parser.add_argument("--executors", default="local,slurm")
    parser.add_argument("--jobs", type=int, default=2,
                        help="studies at once, and Slurm jobs out at once per study")
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    for name in ("mmm", "source", "atlas", "data", "work"):
        setattr(args, name, getattr(args, name).resolve())
    # Patients already made there are kept (they depend only on the atlas
    # and the seed); the cohorts are made afresh.
    args.work.mkdir(parents=True, exist_ok=True)
    for executor in ("local", "slurm", "cluster"):
        shutil.rmtree(args.work / executor, ignore_errors=True)

    patients = {}
    with open(args.work / "patients.csv", "w", newline="") as out:
        writer = csv.writer(out)
        writer.writerow(["id", "patient", "calibration", "frontal", "lateral"])
        for i in range(1, args.patients + 1):
            pid = f"p{i:03d}"
            folder = args.work / "patients" / pid
            if not (folder / "ground_truth.json").is_file():
                shutil.rmtree(folder, ignore_errors=True)
                run([args.mmm, "patient", "synth", "--atlas", args.atlas, "--seed", 100 + i,
                     "-o", folder])
            patients[pid] = folder
            r = folder / "radiographs"
            writer.writerow([pid, pid.upper(), r / "views.json", r / "frontal.png",
                             r / "lateral.png"])

    results = []
    for executor in args.executors.split(","):
        env = dict(os.environ)
        cluster = args.work / "cluster"
        script = args.source / "tests/slurm/local_cluster.sh"
        if executor == "slurm":
            started = run([script, "start", cluster])
            env["SLURM_CONF"] = str(cluster / "slurm.conf")
            if "SLURM_CONF" not in started.stdout:
                fail(f"the local Slurm cluster did not start: {started.stdout}")
        elif executor != "local":
            fail(f"unknown executor '{executor}' (local or slurm)")
        try:
            results.append(one_cohort(args, executor, args.work / "patients.csv", patients, env))
        finally:
            if executor == "slurm":
                subprocess.run([str(script), "stop", str(cluster)], check=False)
        # About 1 GB per study (wrapped muscles and fibres per frame): only
        # the figures are kept.
        shutil.rmtree(args.work / executor, ignore_errors=True)
        r = results[-1]
        print(f"{executor}: {r['patients']} patients, {r['node_executions']} node executions: "
              f"wall {r['wall_seconds']:.0f} s (to the station {r['to_station_seconds']:.0f} s, "
              f"to the end {r['to_end_seconds']:.0f} s; operator {r['operator_seconds']:.0f} s "
              f"apart); per patient median {r['per_patient_median_seconds']:.1f} s, max "
              f"{r['per_patient_max_seconds']:.1f} s", flush=True)
        if r["slurm_seconds_per_node_median"] is not None:
            print(f"  per node execution, time in Slurm beyond the node's own (waiting for free "
                  f"CPUs, allocation, start, end): median "
                  f"{r['slurm_seconds_per_node_median']:.2f} s, 90th percentile "
                  f"{r['slurm_seconds_per_node_p90']:.2f} s", flush=True)
    if len(results) == 2:
        local, slurm = results
        extra = (slurm["wall_seconds"] - local["wall_seconds"]) / slurm["node_executions"]
        print(f"slurm against local: wall x{slurm['wall_seconds'] / local['wall_seconds']:.3f}, "
              f"{extra:+.2f} s of wall time per node execution")
    if args.out:
        args.out.write_text(json.dumps({"end_time": args.end_time, "jobs": args.jobs,
                                        "results": results}, indent=2))


if __name__ == "__main__":
    main()
