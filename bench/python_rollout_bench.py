"""microcobot.stickslip.rollout against the C++ single-axis loop, in the same run.

Workload: 64 axes x 0.1 s of fast stepping (60 V, 500 Hz sawtooth, one voltage sample per 10 us
model step: the samples `stickslip.simulate` records, i.e. the waveform's values at the step ends).
The outputs are caller-owned arrays allocated once (rollout's out= and out_x1=), as the C++ loop
reuses its vectors. Figures: aggregate axis-seconds simulated per wall-clock second, for rollout on 1 and 2 threads,
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
    """(per wall second, per CPU second) of the C++ loop on one axis."""
    p = subprocess.run([bench, "--benchmark_filter=BM_SampleStream", "--benchmark_format=json",
                        "--benchmark_min_time=1"], capture_output=True, text=True, check=True)
    b = json.loads(p.stdout)["benchmarks"][0]
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
    return DURATION_S / (b["real_time"] * scale), DURATION_S / (b["cpu_time"] * scale)


def rollout_axis_seconds_per_s(actuator, voltages, threads, outputs):
    """(per wall second, per CPU second of this process, all threads) of one rollout call, writing
    into caller-owned outputs reused across calls (as BM_SampleStream reuses its vectors)."""
    t0, c0 = time.perf_counter(), time.process_time()
    stickslip.rollout(actuator, None, voltages, threads=threads, operating_point=(60.0, 500.0, "forward"),
                      out=outputs[0], out_x1=outputs[1])
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return N_AXES * DURATION_S / wall, N_AXES * DURATION_S / cpu


def main():
    bench = sys.argv[1] if len(sys.argv) > 1 else "build/release/bench/stickslip_bench"
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    a = stickslip.Actuator()
    u = stickslip.simulate(a, amplitude_V=60.0, frequency_Hz=500.0, duration_s=DURATION_S)["u_V"][1:]
    voltages = np.tile(u, (N_AXES, 1))
    outputs = (np.zeros_like(voltages), np.zeros_like(voltages))  # touched once, here
    best = {k: 0.0 for k in ("cpp_wall", "cpp_cpu", "py1_wall", "py1_cpu", "py2_wall", "py2_cpu")}

    def keep(prefix, rates):
        best[prefix + "_wall"] = max(best[prefix + "_wall"], rates[0])
        best[prefix + "_cpu"] = max(best[prefix + "_cpu"], rates[1])

    load0 = os.getloadavg()
    for r in range(rounds):
        keep("cpp", cpp_axis_seconds_per_s(bench))
        keep("py1", rollout_axis_seconds_per_s(a, voltages, 1, outputs))
        keep("py2", rollout_axis_seconds_per_s(a, voltages, 2, outputs))
        print(f"round {r + 1}: best so far {best}", file=sys.stderr)
    out = {
        "axes": N_AXES, "duration_s": DURATION_S, "cores": os.cpu_count(),
        "axis_s_per_wall_s": {"cpp_1_axis": best["cpp_wall"], "rollout_1_thread": best["py1_wall"],
                              "rollout_2_threads": best["py2_wall"]},
        "axis_s_per_cpu_s": {"cpp_1_axis": best["cpp_cpu"], "rollout_1_thread": best["py1_cpu"],
                             "rollout_2_threads": best["py2_cpu"]},
        # Python's cost against the C++ loop, per CPU second (insensitive to other processes taking
        # the core) and per wall second.
        "python_overhead_cpu": 1.0 - best["py1_cpu"] / best["cpp_cpu"],
        "python_overhead_wall": 1.0 - best["py1_wall"] / best["cpp_wall"],
        "two_thread_speedup_wall": best["py2_wall"] / best["py1_wall"],
        "load_average_before_after": [load0[0], os.getloadavg()[0]],
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
