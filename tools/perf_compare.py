#!/usr/bin/env python3
"""Runs the augocc perf suite and compares it with a baseline (stdlib only).

  perf_compare.py run --binary build/bin/opencv_perf_augocc --baseline perf/baseline.json \
                      --out build/perf_results.json [--filter REGEX] [--repetitions 5]
  perf_compare.py compare --baseline perf/baseline.json --results build/perf_results.json
  perf_compare.py run ... --update-baseline      # writes the results as the new baseline

Medians of the repetitions are compared after dividing each by the median of the calibration
benchmark (Augocc_Calibration) measured in the same process, so a slower or busier machine does
not read as a regression. A benchmark more than --threshold (default 1.25x) slower than the
baseline, normalised, fails the comparison (exit 1).
"""
import argparse
import json
import shutil
import subprocess
import sys

CALIBRATION = "Augocc_Calibration"


def medians(path):
    with open(path) as f:
        data = json.load(f)
    out = {}
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median":
            out[clean(b["run_name"])] = float(b["real_time"]) * unit_scale(b.get("time_unit", "ns"))
    if not out:  # single repetition: no aggregates
        for b in data.get("benchmarks", []):
            if b.get("run_type", "iteration") == "iteration" and "error_occurred" not in b:
                out[clean(b["name"])] = float(b["real_time"]) * unit_scale(b.get("time_unit", "ns"))
    return out


def clean(name):
    for suffix in ("/real_time", "_median"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
    return name


def unit_scale(unit):
    return {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[unit]


def compare(baseline_path, results_path, threshold):
    base = medians(baseline_path)
    res = medians(results_path)
    if CALIBRATION not in base or CALIBRATION not in res:
        print("calibration benchmark missing; comparing raw medians")
        cb = cr = 1.0
    else:
        cb, cr = base[CALIBRATION], res[CALIBRATION]
    print(f"calibration: baseline {cb:.3f} ms, now {cr:.3f} ms (machine factor {cr / cb:.2f})")
    print(f"{'benchmark':60s} {'baseline ms':>12s} {'now ms':>10s} {'ratio':>7s}")
    failed = []
    for name in sorted(res):
        if name == CALIBRATION:
            continue
        now = res[name]
        if name not in base:
            print(f"{name:60s} {'-':>12s} {now:10.3f} {'new':>7s}")
            continue
        ratio = (now / cr) / (base[name] / cb)
        flag = "  REGRESSION" if ratio > threshold else ""
        print(f"{name:60s} {base[name]:12.3f} {now:10.3f} {ratio:7.2f}{flag}")
        if ratio > threshold:
            failed.append(name)
    if failed:
        print(f"{len(failed)} benchmark(s) slower than {threshold}x the baseline: {failed}")
        return 1
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--binary", required=True)
    r.add_argument("--baseline", required=True)
    r.add_argument("--out", required=True)
    r.add_argument("--filter", default="")
    r.add_argument("--repetitions", type=int, default=5)
    r.add_argument("--threshold", type=float, default=1.25)
    r.add_argument("--update-baseline", action="store_true")
    c = sub.add_parser("compare")
    c.add_argument("--baseline", required=True)
    c.add_argument("--results", required=True)
    c.add_argument("--threshold", type=float, default=1.25)
    a = ap.parse_args()
    if a.cmd == "run":
        bench_filter = a.filter
        if bench_filter:  # the calibration always runs alongside
            bench_filter = f"({bench_filter})|{CALIBRATION}"
        cmd = [a.binary, f"--benchmark_repetitions={a.repetitions}",
               "--benchmark_report_aggregates_only=true",
               f"--benchmark_out={a.out}", "--benchmark_out_format=json"]
        if bench_filter:
            cmd.append(f"--benchmark_filter={bench_filter}")
        print(" ".join(cmd), flush=True)
        rc = subprocess.call(cmd)
        if rc != 0:
            return rc
        if a.update_baseline:
            shutil.copyfile(a.out, a.baseline)
            print(f"baseline written: {a.baseline}")
            return 0
        try:
            return compare(a.baseline, a.out, a.threshold)
        except FileNotFoundError:
            print(f"no baseline at {a.baseline}; run with --update-baseline to create it")
            return 0
    return compare(a.baseline, a.results, a.threshold)


if __name__ == "__main__":
    sys.exit(main())
