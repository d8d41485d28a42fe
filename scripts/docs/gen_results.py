#!/usr/bin/python3
"""The results page's benchmark tables, generated from the benchmarks' JSON output.

    scripts/docs/gen_results.py --run build/release/bench [--min-time 0.1] [NAME_bench ...]
        runs the Google Benchmark executables with --benchmark_format=json into bench/results/
        (what `make results` does; the JSON files are committed: the page shows what they hold)
    scripts/docs/gen_results.py --page build/docs-src/benchmarks.md
        replaces the page's `<!-- results:google-benchmark -->` marker with one table per
        benchmark executable, and the machine it ran on (from the JSON's context)

Covered: every C++ benchmark (bench/*_bench.cc: Google Benchmark's JSON). Not covered yet (they
print their own JSON or text; their figures stay in the page with their commands):
bench/serve_bench.mjs (--json), bench/link_bench.mjs, bench/python_rollout_bench.py,
bench/cell_dask_bench.py, bench/scipy_*_bench.py.
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "bench" / "results"
MARKER = "<!-- results:google-benchmark -->"


def run_benches(bench_dir, names, min_time):
    RESULTS.mkdir(parents=True, exist_ok=True)
    exes = sorted(p for p in Path(bench_dir).glob("*_bench") if p.is_file())
    if names:
        exes = [p for p in exes if p.name in names]
    for exe in exes:
        out = RESULTS / f"{exe.name}.json"
        print(f"results: {exe.name}", flush=True)
        subprocess.run([str(exe), f"--benchmark_min_time={min_time}", "--benchmark_format=json",
                        f"--benchmark_out={out}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)


def fmt_time(value, unit):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[unit]
    s = value * scale
    for u, f in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6), ("ns", 1e-9)):
        if s >= f:
            return f"{s / f:.3g} {u}"
    return f"{s / 1e-9:.3g} ns"


def fmt_num(v):
    if isinstance(v, (int, float)):
        a = abs(v)
        if a >= 1e6 or (a and a < 1e-3):
            return f"{v:.3g}"
        return f"{v:.4g}"
    return str(v)


SKIP = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads", "iterations", "real_time",
        "cpu_time", "time_unit", "family_index", "per_family_instance_index", "aggregate_name", "aggregate_unit",
        "label", "error_occurred", "error_message"}


def tables():
    files = sorted(RESULTS.glob("*.json"))
    if not files:
        return ("No benchmark results yet: `make results` runs the benchmarks and writes them to "
                "`bench/results/`.\n")
    out = []
    machines = {}
    for f in files:
        data = json.loads(f.read_text())
        ctx = data.get("context", {})
        machine = (f"{ctx.get('num_cpus', '?')} CPUs at {ctx.get('mhz_per_cpu', '?')} MHz, "
                   f"{ctx.get('library_build_type', '?')} Google Benchmark, load average "
                   f"{', '.join(f'{x:.1f}' for x in ctx.get('load_avg', []))} when it ran")
        machines.setdefault(machine, []).append(f.stem)
        rows = [b for b in data.get("benchmarks", []) if b.get("run_type", "iteration") == "iteration"]
        counters = sorted({k for b in rows for k, v in b.items() if k not in SKIP and isinstance(v, (int, float))})
        out.append(f"### {f.stem}\n")
        out.append(f"`build/release/bench/{f.stem} --benchmark_format=json` (source `bench/{f.stem}.cc`); "
                   f"{machine}.\n")
        head = "| benchmark | wall time | CPU time | iterations |" + "".join(f" {c} |" for c in counters)
        out.append(head)
        out.append("|---" * (4 + len(counters)) + "|")
        for b in rows:
            cells = [f"`{b['name']}`", fmt_time(b["real_time"], b["time_unit"]), fmt_time(b["cpu_time"], b["time_unit"]),
                     str(b.get("iterations", ""))] + [fmt_num(b[c]) if c in b else "" for c in counters]
            out.append("| " + " | ".join(cells) + " |")
        out.append("")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description="Benchmark results: run the benchmarks (JSON) or render their tables")
    ap.add_argument("--run", metavar="BENCH_DIR", help="run the *_bench executables of this directory")
    ap.add_argument("--min-time", default="0.1", help="--benchmark_min_time per benchmark, s (default 0.1)")
    ap.add_argument("--page", help="the page whose marker is replaced by the tables")
    ap.add_argument("names", nargs="*", help="only these executables (e.g. dsp_bench)")
    args = ap.parse_args()
    if args.run:
        run_benches(args.run, args.names, args.min_time)
    if args.page:
        page = Path(args.page)
        text = page.read_text()
        if MARKER not in text:
            sys.exit(f"gen_results: {page} has no {MARKER}")
        page.write_text(text.replace(MARKER, tables()))


if __name__ == "__main__":
    main()
