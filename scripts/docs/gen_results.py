#!/usr/bin/python3
"""The results page's benchmark tables, generated from the benchmarks' JSON output.

    scripts/docs/gen_results.py --run build/release/bench [--min-time 0.1] [NAME ...]
        runs the Google Benchmark executables of that directory with --benchmark_format=json, then
        the Node and Python benchmarks (SCRIPTS below: short settings for a 2-core machine), one at
        a time, into bench/results/NAME.json (what `make results` does; the JSON files are
        committed: the page shows what they hold). NAME (e.g. dsp_bench, serve_bench) runs only those.
    scripts/docs/gen_results.py --page build/docs-src/benchmarks.md
        replaces the page's `<!-- results:google-benchmark -->` marker with one table per
        benchmark executable, and `<!-- results:scripts -->` with one table per script: its
        figures, the command that reproduced them and the machine it ran on. A script's JSON
        missing is an error naming the file and the command that writes it.

Covered: every C++ benchmark (bench/*_bench.cc: Google Benchmark's JSON) and the scripts of
SCRIPTS (their JSON on stdout, kept under "results" beside a "context" this script adds: host,
CPU model, cores, the command line, the load average before and after). Not covered: the 30-minute
soak (bench/soak.mjs), whose figures the page quotes by hand, and the bench/ scripts it does not quote.
"""

import argparse
import json
import os
import shlex
import socket
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "bench" / "results"
GB_MARKER = "<!-- results:google-benchmark -->"
SCRIPTS_MARKER = "<!-- results:scripts -->"

# The Node and Python benchmarks: name -> (what it measures, the command printing its JSON, run from
# the repository's root; {bench}, {cli}, {python} are the build's benchmark directory, command line
# and Python module). Shorter than their defaults where a default takes minutes: serve_bench and
# link_bench 5 s phases (default 15), cell_dask_bench 1 round of 4 seeds x 2 parts (default 2 x 4 x 3).
SCRIPTS = {
    "serve_bench": ("`microcobot serve` on loopback: the operator's command to the actuator target (the "
                    "loop tick that applies it), and the loop's tick without and with 8 clients on every "
                    "channel (wall clock `tick_us`, loop thread CPU `tick_cpu_us`).",
                    "MC_CLI={cli} node --experimental-websocket bench/serve_bench.mjs --phase-s 5 --json"),
    "link_bench": ("The distributed platform over DDS: the loops' ticks of one process, one beside another, "
                   "slave and master (jogging, then holding without a client), the link's own work on the "
                   "slave's loop (`link_cost_us`), and the master → slave → master round trip at 1 kHz "
                   "(`round_trip_ms`, 5000 targets).",
                   "MC_CLI={cli} node --experimental-websocket bench/link_bench.mjs --phase-s 5 --json"),
    "python_rollout_bench": ("`stickslip.rollout` of 64 axes x 0.1 s against the C++ loop on one axis "
                             "(`BM_SampleStream`): axis-seconds simulated per wall and per CPU second, "
                             "the best of 3 rounds each.",
                             "PYTHONPATH={python} /usr/bin/python3 bench/python_rollout_bench.py "
                             "{bench}/stickslip_bench 3"),
    "python_positioner_bench": ("`positioner.Positioner`'s vectorised calls over 20 000 reachable poses: "
                                "ns per pose (ik and jacobian with the workspace check of every pose, fk "
                                "by Newton from home or from a guess 1 um / 1 urad away), the best of 3 "
                                "rounds, and the bytes one ik call allocates with and without out=.",
                                "PYTHONPATH={python} /usr/bin/python3 bench/python_positioner_bench.py 20000 3"),
    "cell_dask_bench": ("`cell.batch` on a Dask LocalCluster of 2 worker processes against 1, the same "
                        "campaign of automatic cycles (wall seconds of each, and the speed-up).",
                        "PYTHONPATH={python} /usr/bin/python3 bench/cell_dask_bench.py 1 4 2"),
    "scipy_sos_bench": ("SOS filtering of 65 536 samples, ns per sample per section: the block path, the "
                        "previous section-by-section loop and `scipy.signal.sosfilt`, and their ratios.",
                        "/usr/bin/python3 bench/scipy_sos_bench.py {bench}/dsp_bench --json"),
    "scipy_welch_bench": ("Welch PSD of 1e6 samples: `scipy.signal.welch` against microcobot's, ms, and "
                          "their ratio.",
                          "/usr/bin/python3 bench/scipy_welch_bench.py {bench}/dsp_bench --json"),
}


def run_benches(bench_dir, names, min_time):
    exes = sorted(p for p in Path(bench_dir).glob("*_bench") if p.is_file())
    if names:
        exes = [p for p in exes if p.name in names]
    for exe in exes:
        out = RESULTS / f"{exe.name}.json"
        print(f"results: {exe.name}", flush=True)
        subprocess.run([str(exe), f"--benchmark_min_time={min_time}", "--benchmark_format=json",
                        f"--benchmark_out={out}", "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)


def cpu_model():
    with open("/proc/cpuinfo") as f:
        return next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), "unknown CPU")


def run_scripts(bench_dir, names):
    build = Path(bench_dir).resolve().parent
    paths = {k: shlex.quote(os.path.relpath(p, ROOT)) for k, p in
             (("bench", Path(bench_dir).resolve()), ("cli", build / "apps" / "microcobot" / "microcobot"),
              ("python", build / "python"))}
    for name, (_, command) in SCRIPTS.items():
        if names and name not in names:
            continue
        command = command.format(**paths)
        print(f"results: {name}: {command}", flush=True)
        before = os.getloadavg()[0]
        out = subprocess.run(command, shell=True, cwd=ROOT, stdout=subprocess.PIPE, text=True, check=True).stdout
        context = {"host": socket.gethostname(), "cpu": cpu_model(), "cores": os.cpu_count(), "command": command,
                   "load_avg_before": before, "load_avg_after": os.getloadavg()[0]}
        (RESULTS / f"{name}.json").write_text(json.dumps({"context": context, "results": json.loads(out)},
                                                         indent=1) + "\n")


def fmt_time(value, unit):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[unit]
    s = value * scale
    for u, f in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6), ("ns", 1e-9)):
        if s >= f:
            return f"{s / f:.3g} {u}"
    return f"{s / 1e-9:.3g} ns"


def fmt_num(v):
    if isinstance(v, list):
        return ", ".join(fmt_num(x) for x in v)
    if isinstance(v, int) and not isinstance(v, bool):
        return str(v)
    if isinstance(v, float):
        a = abs(v)
        if a >= 1e6 or (a and a < 1e-3):
            return f"{v:.3g}"
        return f"{v:.0f}" if a >= 1e4 else f"{v:.4g}"  # 12345, not 1.234e+04
    return str(v)


SKIP = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads", "iterations", "real_time",
        "cpu_time", "time_unit", "family_index", "per_family_instance_index", "aggregate_name", "aggregate_unit",
        "label", "error_occurred", "error_message"}


def tables():
    files = sorted(f for f in RESULTS.glob("*.json") if f.stem not in SCRIPTS)
    if not files:
        return ("No benchmark results yet: `make results` runs the benchmarks and writes them to "
                "`bench/results/`.\n")
    out = []
    for f in files:
        data = json.loads(f.read_text())
        ctx = data.get("context", {})
        machine = (f"{ctx.get('num_cpus', '?')} CPUs at {ctx.get('mhz_per_cpu', '?')} MHz, "
                   f"{ctx.get('library_build_type', '?')} Google Benchmark, load average "
                   f"{', '.join(f'{x:.1f}' for x in ctx.get('load_avg', []))} when it ran")
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


def figure_rows(data, path=""):
    """(figure, values) rows of a script's JSON: a top-level figure on its own row, the figures of a
    nested object on one row named by its path (`tick_us.with_clients`: samples, p50, p99)."""
    rows, group = [], []
    for key, value in data.items():
        name = f"{path}.{key}" if path else key
        if isinstance(value, dict):
            rows += figure_rows(value, name)
        elif path:
            group.append(f"{key} {fmt_num(value)}")
        else:
            rows.append((name, fmt_num(value)))
    return ([(path, ", ".join(group))] if group else []) + rows


def script_tables():
    out = []
    for name, (what, _) in SCRIPTS.items():
        f = RESULTS / f"{name}.json"
        if not f.exists():
            sys.exit(f"gen_results: {f} is missing: `scripts/docs/gen_results.py --run build/release/bench {name}` "
                     f"runs the benchmark and writes it")
        data = json.loads(f.read_text())
        ctx = data["context"]
        out.append(f"### {name}\n")
        out.append(f"{what} `{ctx['command']}`; on {ctx['host']} ({ctx['cpu']}, {ctx['cores']} cores), load "
                   f"average {ctx['load_avg_before']:.1f} before the run and {ctx['load_avg_after']:.1f} after.\n")
        out += ["| figure | values |", "|---|---|"]
        out += [f"| `{figure}` | {values} |" for figure, values in figure_rows(data["results"])]
        out.append("")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description="Benchmark results: run the benchmarks (JSON) or render their tables")
    ap.add_argument("--run", metavar="BENCH_DIR", help="run the *_bench executables of this directory, then SCRIPTS")
    ap.add_argument("--min-time", default="0.1", help="--benchmark_min_time per benchmark, s (default 0.1)")
    ap.add_argument("--page", help="the page whose markers are replaced by the tables")
    ap.add_argument("names", nargs="*", help="only these (e.g. dsp_bench, serve_bench)")
    args = ap.parse_args()
    if args.run:
        unknown = set(args.names) - {p.name for p in Path(args.run).glob("*_bench")} - SCRIPTS.keys()
        if unknown:
            sys.exit(f"gen_results: no benchmark named {', '.join(sorted(unknown))}")
        RESULTS.mkdir(parents=True, exist_ok=True)
        run_benches(args.run, args.names, args.min_time)
        run_scripts(args.run, args.names)
    if args.page:
        page = Path(args.page)
        text = page.read_text()
        for marker in (GB_MARKER, SCRIPTS_MARKER):
            if marker not in text:
                sys.exit(f"gen_results: {page} has no {marker}")
        page.write_text(text.replace(GB_MARKER, tables()).replace(SCRIPTS_MARKER, script_tables()))


if __name__ == "__main__":
    main()
