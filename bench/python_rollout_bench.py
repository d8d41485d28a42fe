"""microcobot.stickslip.rollout against the C++ single-axis loop, in the same run (issue #16).

Workload: 64 axes x 0.1 s of fast stepping (60 V, 500 Hz sawtooth, one voltage sample per 10 us
model step: the samples `stickslip.simulate` records, i.e. the waveform's values at the step ends).
Figures: aggregate axis-seconds simulated per wall-clock second, for rollout on 1 and 2 threads,
and for the C++ benchmark BM_SampleStream (bench/stickslip_bench.cc: the same loop on one axis,
no Python). Rounds alternate C++ / 1 thread / 2 threads and the best round of each is kept (the
machine is shared: the best is the least disturbed).

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_rollout_bench.py \
        build/release/bench/stickslip_bench [rounds]
"""

import json
import os
import subprocess
import sys
import time

import numpy as np

from microcobot import stickslip

N_AXES, DURATION_S = 64, 0.1


def cpp_axis_seconds_per_s(bench):
    p = subprocess.run([bench, "--benchmark_filter=BM_SampleStream", "--benchmark_format=json",
                        "--benchmark_min_time=1"], capture_output=True, text=True, check=True)
    b = json.loads(p.stdout)["benchmarks"][0]
    return b["rtf"]


def rollout_axis_seconds_per_s(actuator, voltages, threads):
    t0 = time.perf_counter()
    stickslip.rollout(actuator, None, voltages, threads=threads, operating_point=(60.0, 500.0, "forward"))
    return N_AXES * DURATION_S / (time.perf_counter() - t0)


def main():
    bench = sys.argv[1] if len(sys.argv) > 1 else "build/release/bench/stickslip_bench"
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    a = stickslip.Actuator()
    u = stickslip.simulate(a, amplitude_V=60.0, frequency_Hz=500.0, duration_s=DURATION_S)["u_V"][1:]
    voltages = np.tile(u, (N_AXES, 1))
    best = {"cpp": 0.0, "py1": 0.0, "py2": 0.0}
    for r in range(rounds):
        best["cpp"] = max(best["cpp"], cpp_axis_seconds_per_s(bench))
        best["py1"] = max(best["py1"], rollout_axis_seconds_per_s(a, voltages, 1))
        best["py2"] = max(best["py2"], rollout_axis_seconds_per_s(a, voltages, 2))
        print(f"round {r + 1}: best so far {best}", file=sys.stderr)
    overhead = 1.0 - best["py1"] / best["cpp"]
    scaling = best["py2"] / best["py1"]
    out = {
        "axes": N_AXES, "duration_s": DURATION_S, "cores": os.cpu_count(),
        "cpp_axis_s_per_s": best["cpp"], "rollout_1_thread_axis_s_per_s": best["py1"],
        "rollout_2_threads_axis_s_per_s": best["py2"],
        "python_overhead": overhead, "two_thread_speedup": scaling,
        "load_average": os.getloadavg(),
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
