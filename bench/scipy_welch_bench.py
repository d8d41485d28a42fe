#!/usr/bin/python3
"""scipy.signal.welch on 1e6 samples against mc::dsp::welch on the same data, one run.

    /usr/bin/python3 bench/scipy_welch_bench.py build/dsp/bench/dsp_bench [--json]

With --json, the same figures as one JSON object (per nperseg) instead of the text.
"""
import json, os, subprocess, sys, tempfile, timeit
import numpy as np
import scipy.signal as sig

as_json = "--json" in sys.argv[1:]
dsp_bench = next(a for a in sys.argv[1:] if a != "--json")
x = np.random.default_rng(1).standard_normal(1_000_000)
path = os.path.join(tempfile.gettempdir(), "mc_welch_data.f64")
x.astype("<f8").tofile(path)
out = subprocess.run([dsp_bench, "--benchmark_filter=BM_Welch1e6", "--benchmark_format=json"],
                     env={**os.environ, "MC_WELCH_DATA": path}, capture_output=True, text=True, check=True)
ours = {b["name"]: b["real_time"] for b in json.loads(out.stdout)["benchmarks"]}
result = {"samples": len(x)}
for nperseg in (256, 1024):
    t = min(timeit.repeat(lambda: sig.welch(x, fs=10000.0, nperseg=nperseg), number=5, repeat=3)) / 5 * 1e3
    mc = ours[f"BM_Welch1e6/{nperseg}"]
    result[f"nperseg_{nperseg}"] = {"scipy_ms": t, "microcobot_ms": mc, "scipy_over_microcobot": t / mc}
    if not as_json:
        print(f"nperseg={nperseg}: scipy {t:.2f} ms, microcobot {mc:.2f} ms, scipy/microcobot = {t / mc:.2f}")
if as_json:
    print(json.dumps(result, indent=1))
