#!/usr/bin/env python3
"""Seeded random cases of `microcobot vision track --target tool`: the tool's tips
followed at the objectives asked (5x/10x unless --objectives), 0-60 um/s in any direction, 60 frames
at 30 fps, the default sensor's noise, against the simulation's truth. The figures of
docs/parameters.md ("Tracking the tool's tips", the tuning set: --seed 28) and docs/benchmarks.md
(the validation set: --seed 4111).

Usage: scripts/tool_tracking_cases.py --cli build/release/apps/microcobot/microcobot
           [--seed 4111] [--cases 16] [--objectives 2x,5x,10x,20x,50x] [--highpass 1.5[,0,...]]
           [--above 0[,24,...]] [--side-um 0[,50,...]] [--verbose]

Each (template offset, high-pass, template side) runs the same cases; a line per triple gives the
median and worst rms error in px, and with several objectives the worst per objective. A side of
0 is the command's default (the tool's default side in the object); --side-px gives sides in
pixels instead.
"""
import argparse
import json
import random
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor


def cases(seed, n, objectives):
    rng = random.Random(seed)
    out = []
    for _ in range(n):
        objective = rng.choice(objectives)
        speed, direction, noise_seed = rng.uniform(0, 60), rng.uniform(-180, 180), rng.randrange(1, 10**6)
        out.append((objective, speed, direction, noise_seed))
    return out


def track(cli, case, highpass, above, side, side_unit):
    objective, speed, direction, noise_seed = case
    args = [cli, "vision", "track", "--target", "tool", "--objective", objective, "--speed-um-s", f"{speed:.3f}",
            "--direction-deg", f"{direction:.2f}", "--seed", str(noise_seed), "--frames", "60",
            "--highpass-px", str(highpass), "--template-above-px", str(above), "--json"]
    if side > 0:
        args += [f"--template-{side_unit}", f"{side:g}"]
    out = subprocess.run(args, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"tool_tracking_cases: {' '.join(args)} failed: {out.stderr.strip()}")
    return json.loads(out.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--seed", type=int, default=4111)
    ap.add_argument("--cases", type=int, default=16)
    ap.add_argument("--objectives", default="5x,10x", help="comma-separated objectives the cases are drawn from")
    ap.add_argument("--highpass", default="1.5", help="comma-separated sigmas [px]")
    ap.add_argument("--above", default="0", help="comma-separated template offsets above the tool point [px]")
    sides = ap.add_mutually_exclusive_group()
    sides.add_argument("--side-um", default="0", help="comma-separated template sides in the object [um] (0: default)")
    sides.add_argument("--side-px", help="comma-separated template sides [px]")
    ap.add_argument("--verbose", action="store_true", help="a line per case")
    a = ap.parse_args()
    objectives = a.objectives.split(",")
    todo = cases(a.seed, a.cases, objectives)
    unit = "px" if a.side_px else "um"
    side_list = [float(x) for x in (a.side_px or a.side_um).split(",")]
    print(f"seed {a.seed}, {a.cases} cases over {','.join(objectives)}: above_px highpass_px side_{unit} | "
          f"median_rms_px worst_rms_px worst_max_px | worst rms per objective")
    for above in [float(x) for x in a.above.split(",")]:
        for highpass in [float(x) for x in a.highpass.split(",")]:
            for side in side_list:
                with ThreadPoolExecutor(2) as pool:
                    results = list(pool.map(lambda c: track(a.cli, c, highpass, above, side, unit), todo))
                if a.verbose:
                    for c, d in zip(todo, results):
                        print(f"    {c[0]:>4} {c[1]:5.1f} um/s {c[2]:+7.1f} deg | {d['template_px']} px | "
                              f"{d['found']}/60 rms {d['rms_error_px']:.4f} max {d['max_error_px']:.4f} "
                              f"bias ({d['bias_px'][0]:+.4f}, {d['bias_px'][1]:+.4f})")
                rms = [d["rms_error_px"] for d in results]
                per = {}
                for c, d in zip(todo, results):
                    per[c[0]] = max(per.get(c[0], 0.0), d["rms_error_px"])
                per_text = " ".join(f"{o} {per[o]:.4f}" for o in objectives if o in per)
                print(f"  {above:6g} {highpass:6g} {side:6g} | {statistics.median(rms):.4f} {max(rms):.4f} "
                      f"{max(d['max_error_px'] for d in results):.4f} | {per_text}")


if __name__ == "__main__":
    main()
