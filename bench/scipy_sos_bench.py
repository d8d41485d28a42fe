#!/usr/bin/python3
"""scipy.signal.sosfilt against mc::dsp::SosFilter::process (block) and the previous
section-by-section block loop, on the same filters and block length, in one run.

    /usr/bin/python3 bench/scipy_sos_bench.py build/<dir>/bench/dsp_bench [--json]

Prints ns per sample per section (CPU time for ours, best of 5 for scipy) and the ratios; with
--json, the same figures as one JSON object (per number of sections) instead of the text.
"""
import json, subprocess, sys, timeit
import numpy as np
import scipy.signal as sig

as_json = "--json" in sys.argv[1:]
dsp_bench = next(a for a in sys.argv[1:] if a != "--json")
n = 65536
x = np.random.default_rng(1).standard_normal(n)
out = subprocess.run([dsp_bench, "--benchmark_filter=BM_SosFilterBlock", "--benchmark_min_time=0.2",
                      "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true",
                      "--benchmark_format=json"], capture_output=True, text=True, check=True)
# the counter is an inverted rate: seconds per sample-section
ours = {b["run_name"]: b["ns_per_sample_section"] * 1e9 for b in json.loads(out.stdout)["benchmarks"]
        if b.get("aggregate_name") == "median"}
result = {"samples": n}
for sections in (1, 2, 4, 8):
    sos = sig.butter(2 * sections, 500.0, fs=10000.0, output="sos")
    t = min(timeit.repeat(lambda: sig.sosfilt(sos, x), number=20, repeat=5)) / 20 / (n * sections) * 1e9
    new = ours[f"BM_SosFilterBlock/{sections}"]
    old = ours[f"BM_SosFilterBlockSectionBySection/{sections}"]
    result[f"sections_{sections}"] = {"block_ns": new, "section_by_section_ns": old, "scipy_ns": t,
                                      "section_by_section_over_block": old / new, "scipy_over_block": t / new}
    if not as_json:
        print(f"{sections} section(s): block path {new:.2f} ns, section by section {old:.2f} ns, scipy {t:.2f} ns;"
              f" section-by-section/block = {old / new:.2f}, scipy/block = {t / new:.2f}")
if as_json:
    print(json.dumps(result, indent=1))
