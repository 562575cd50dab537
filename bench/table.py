"""Turns Google Benchmark JSON (aggregates over repetitions) into the suite
table: one row per benchmark with the median time, the spread (coefficient of
variation), the throughput and the per-item time. Prints the table and writes
the same figures as JSON."""

import json
import os
import sys


def main(suite, raw_path, out_path, build_type="unknown"):
    with open(raw_path, encoding="utf-8") as f:
        raw = json.load(f)
    rows = {}
    for b in raw["benchmarks"]:
        # "/iterations:1" only says each repetition is one batch: not a name.
        name = b["run_name"].replace("/iterations:1", "")
        row = rows.setdefault(name, {"benchmark": name})
        aggregate = b.get("aggregate_name")
        # One repetition has no aggregates: its single run is the median.
        single = b.get("run_type") == "iteration" and "median_time" not in row
        if aggregate == "median" or single:
            row["median_time"] = b["real_time"]
            row["unit"] = b["time_unit"]
            if "items_per_second" in b:
                row["items_per_second"] = b["items_per_second"]
                row["ns_per_item"] = 1e9 / b["items_per_second"]
            for key, value in b.items():
                if key in ("faces", "inside_fraction"):
                    row[key] = value
        elif aggregate == "cv":
            row["cv_percent"] = 100.0 * b["real_time"]
        row["repetitions"] = b.get("repetitions", 1)
    table = list(rows.values())
    context = raw["context"]
    header = (f"suite {suite}: medians of {table[0]['repetitions'] if table else 0} repetitions, "
              f"{context.get('num_cpus')} CPUs, mmm built {build_type}, "
              f"load average {', '.join(f'{x:.1f}' for x in context.get('load_avg', []))}")
    print(header)
    print(f"{'benchmark':<24} {'median':>12} {'cv%':>6} {'items/s':>14} {'ns/item':>10}")
    for r in table:
        items = f"{r['items_per_second']:.3e}" if "items_per_second" in r else "-"
        per_item = f"{r['ns_per_item']:.1f}" if "ns_per_item" in r else "-"
        print(f"{r['benchmark']:<24} {r['median_time']:>9.3f} {r['unit']:<2} "
              f"{r.get('cv_percent', 0):>6.1f} {items:>14} {per_item:>10}")
    document = {"suite": suite, "build_type": build_type, "context": context,
                "results": table}
    # Suites that also measure accuracy (e.g. scaling) leave SUITE.accuracy.txt
    # (the table people read) and SUITE.accuracy.json beside the raw output.
    base = os.path.join(os.path.dirname(raw_path), suite)
    if os.path.exists(base + ".accuracy.json"):
        with open(base + ".accuracy.json", encoding="utf-8") as f:
            document["accuracy"] = json.load(f)
        with open(base + ".accuracy.txt", encoding="utf-8") as f:
            print(f.read())
    with open(out_path, "w", encoding="utf-8") as f:
        json.dump(document, f, indent=2)
    print(f"written {out_path}")


if __name__ == "__main__":
    main(*sys.argv[1:5])
