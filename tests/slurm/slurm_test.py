#!/usr/bin/env python3
"""Node executions as Slurm jobs, on a real single-node Slurm cluster started
here (tests/slurm/local_cluster.sh: munged, slurmctld, slurmd on localhost).

  1. A study (schemas/examples/mesh_demo.yaml: load, simplify, measure a
     muscle surface) run with `--executor slurm`: every node ran as a Slurm
     job (its log says which), and the outputs are byte for byte those of the
     same study run locally.
  2. A job cancelled with scancel (the partition held down so that it waits
     in the queue): the run fails naming the job's state, CANCELLED; run
     again with the partition up, the node is submitted again and the study
     finishes.
  3. A killed coordinator (SIGKILL, its job waiting in the queue) leaves no
     job behind: Slurm lists the job as CANCELLED at once.
  4. `mmm cohort run --executor slurm` on two studies: both done.
  5. The overhead: per node, the Slurm run's time less the local run's
     (printed; the median is stated in docs/benchmarks.md).

Usage: slurm_test.py --mmm MMM --source REPO --data DATA --work DIR
"""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


class Runner:
    def __init__(self, args, env):
        self.args = args
        self.env = env
        self.log = open(args.work / "log.txt", "w")

    def __call__(self, argv, expect=(0,)):
        argv = [str(a) for a in argv]
        result = subprocess.run(argv, capture_output=True, text=True, env=self.env)
        self.log.write(f"$ {' '.join(argv)}\n{result.stdout}{result.stderr}\n")
        self.log.flush()
        if result.returncode not in expect:
            fail(f"{' '.join(argv)} exited {result.returncode}:\n{result.stdout}\n{result.stderr}")
        return result


def node_seconds(run, study, node):
    """The time of the node's last execution, from `mmm explain`."""
    text = run([run.args.mmm, "explain", study, node]).stdout
    seconds = None
    for line in text.splitlines():
        parts = line.split()
        if len(parts) > 4 and parts[0].startswith("#") and parts[1] == "done":
            seconds = float(parts[3])
    if seconds is None:
        fail(f"no finished execution of {node} in {study}:\n{text}")
    return seconds


def main():
    parser = argparse.ArgumentParser()
    for name in ("mmm", "source", "data", "work"):
        parser.add_argument(f"--{name}", type=Path, required=True)
    args = parser.parse_args()
    for name in ("mmm", "source", "data", "work"):
        setattr(args, name, getattr(args, name).resolve())
    if args.work.exists():
        shutil.rmtree(args.work)
    args.work.mkdir(parents=True)
    cluster = args.work / "cluster"
    script = args.source / "tests/slurm/local_cluster.sh"
    started = subprocess.run([str(script), "start", str(cluster)], capture_output=True, text=True)
    if started.returncode != 0:
        fail(f"the local Slurm cluster did not start:\n{started.stdout}{started.stderr}")
    env = dict(os.environ, SLURM_CONF=str(cluster / "slurm.conf"))
    try:
        run = Runner(args, env)
        workflow = args.source / "schemas/examples/mesh_demo.yaml"
        surface = args.data / "vhf/Right/VHF_Right_Muscle_SuperiorGemellus_smooth.stl"

        def study(name):
            path = args.work / name
            run([args.mmm, "study", "create", path, "-w", workflow, "-i", f"surface={surface}"])
            return path

        # 1. Slurm against local.
        local, remote = study("local"), study("slurm")
        run([args.mmm, "run", local])
        run([args.mmm, "run", remote, "--executor", "slurm"])
        for node in ("load", "simplify", "measure"):
            if "ran as Slurm job" not in run([args.mmm, "explain", remote, node]).stdout:
                fail(f"node {node} did not run as a Slurm job")
        for exported in sorted((local / "outputs").iterdir()):
            if exported.is_file() and exported.suffix != ".json":
                if exported.read_bytes() != (remote / "outputs" / exported.name).read_bytes():
                    fail(f"{exported.name} differs between the local and the Slurm run")
        overhead = [node_seconds(run, remote, n) - node_seconds(run, local, n)
                    for n in ("load", "simplify", "measure")]

        # 2. scancel.
        cancelled = study("cancelled")
        run(["scontrol", "update", "PartitionName=mmm", "State=DOWN"])
        runner = subprocess.Popen([str(args.mmm), "run", str(cancelled), "--executor", "slurm"],
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                  env=env)
        job = None
        deadline = time.time() + 60
        while job is None and time.time() < deadline:
            queued = run(["squeue", "-h", "-n", "mmm-load", "-o", "%i %T"]).stdout.split()
            job = queued[0] if queued else None
            time.sleep(0.1)
        if job is None:
            fail("the job never appeared in the queue")
        run(["scancel", job])
        output, _ = runner.communicate(timeout=60)
        run(["scontrol", "update", "PartitionName=mmm", "State=UP"])
        if runner.returncode != 1 or "CANCELLED" not in output:
            fail(f"a cancelled job was not reported as such (exit {runner.returncode}):\n{output}")
        run([args.mmm, "run", cancelled, "--executor", "slurm"])
        history = run([args.mmm, "explain", cancelled, "load"]).stdout
        if "failed" not in history or "done" not in history:
            fail(f"the cancelled execution and its re-run are not both recorded:\n{history}")

        # 3. The coordinator killed while its job waits: the job goes too.
        orphan = study("orphan")
        run(["scontrol", "update", "PartitionName=mmm", "State=DOWN"])
        runner = subprocess.Popen([str(args.mmm), "run", str(orphan), "--executor", "slurm"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        waiting = None
        deadline = time.time() + 60
        while waiting is None and time.time() < deadline:
            queued = run(["squeue", "-h", "-n", "mmm-load", "-t", "PENDING", "-o", "%i"])
            waiting = queued.stdout.split()[0] if queued.stdout.split() else None
            time.sleep(0.1)
        if waiting is None:
            fail("the orphan test's job never appeared in the queue")
        runner.kill()
        runner.wait()
        state = ""
        deadline = time.time() + 30
        while state != "CANCELLED" and time.time() < deadline:
            state = run(["squeue", "-h", "-t", "all", "-j", waiting, "-o", "%T"]).stdout.strip()
            time.sleep(0.1)
        run(["scontrol", "update", "PartitionName=mmm", "State=UP"])
        if state != "CANCELLED":
            fail(f"job {waiting} outlived its killed coordinator (state {state})")

        # 4. A cohort on Slurm.
        root = args.work / "cohort"
        patients = args.work / "patients.csv"
        patients.write_text(f"id,surface\na,{surface}\nb,{surface}\n")
        run([args.mmm, "cohort", "create", root, "-w", workflow, "--patients", patients])
        run([args.mmm, "cohort", "run", root, "-j", "2", "--executor", "slurm"])
        status = run([args.mmm, "cohort", "status", root]).stdout
        if not status.startswith("2 studies: 2 done"):
            fail(f"the Slurm cohort is not done:\n{status}")
        print(f"slurm: 3 nodes as jobs, outputs identical to a local run; a scancelled job "
              f"recorded ({job}) and re-run; a killed coordinator's job cancelled "
              f"({waiting}); a 2-study cohort done; overhead per node "
              f"{', '.join(f'{o:.2f}' for o in overhead)} s (median "
              f"{statistics.median(overhead):.2f} s)")
    finally:
        subprocess.run([str(script), "stop", str(cluster)], check=False)


if __name__ == "__main__":
    main()
