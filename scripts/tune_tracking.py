#!/usr/bin/python3
"""Seeded (1+1) random search of the tracking controller's gains on the TUNING set only.

Every trial writes a parameter file (the present best with 1-4 of the searched values perturbed by
log-normal steps, additive for kp), runs `microcobot control validate --set tuning --params FILE --json`
and keeps the trial if its cost is lower. The validation set is never run here: judge the result
with `microcobot control validate --params BEST.yaml` afterwards. Deterministic for a given binary,
--seed, --trials and start file (the simulation is deterministic, the perturbations come from
random.Random(seed)).

A trial is kept only if it also meets the hard constraint the unit tests assert: a 400 nm move
(inside the PE's stroke) only scans, with no step and a max error <= 30 nm (`control trajectory
--profile trapezoid --distance 4e-7 --velocity 2e-4`). --freeze keeps named values at their start;
--fixed KEY=VALUE writes a value the search leaves alone into every trial (a design, such as a split
edge, tried with the searched gains retuned around it).

Cost (lower is better), on the tuning set's per-case figures:
    mean RMS / 100 nm
  + 4 * sum over cases of the relative excess over each goal (RMS 150 nm, max 300 nm, path
    deviation 200 nm, backward from power-up 250 nm)
  + 4 * the relative excess of the median RMS over 100 nm
  + the worst RMS / 150 nm + the worst max / 300 nm (pull the tail in even when all goals hold)

Usage (run it at low priority, single-threaded; each trial is one validate run; give it a copy of the
binary, so that a rebuild does not change it under the search):
  nice -n 10 /usr/bin/python3 scripts/tune_tracking.py --cli build/release/apps/microcobot/microcobot \
      --trials 60 --seed 1 --out /tmp/tune
writes /tmp/tune/trials.jsonl (every trial: values, cost, summary) and /tmp/tune/best.yaml.
"""

import argparse
import json
import math
import os
import random
import subprocess
import sys

# The searched values: (key, lower bound, upper bound, kind). "log": multiplicative steps; "lin":
# additive steps of `scale` * (hi - lo). The bounds keep TrackingParams::validate() satisfied.
SEARCHED = [
    ("low_V", 20.0, 45.0, "lin"),
    ("sprint_low_V", 7.5, 30.0, "lin"),
    ("unload_V", 20.0, 62.0, "lin"),
    ("sprint_velocity_m_s", 300e-6, 1.2e-3, "log"),
    ("sprint_lag_m", 0.3e-6, 1.5e-6, "log"),
    ("sprint_horizon_s", 0.0, 20e-3, "lin"),
    ("edge_ready_V", 3.0, 25.0, "log"),
    ("lead_m", 200e-9, 1.2e-6, "log"),
    ("lead_window_m", 80e-9, 600e-9, "log"),
    ("catchup_s", 0.3e-3, 1.5e-3, "log"),
    ("settle_s", 0.1e-3, 1.0e-3, "log"),
    ("ki_1_s", 300.0, 5000.0, "log"),
    ("kp", -0.8, 0.0, "lin"),
    ("backslip_gain", 0.05, 0.9, "log"),
    ("lead_fraction", 0.3, 1.0, "lin"),
    ("damp_gain", 0.0, 1.0, "lin"),
    ("damp_lag_ticks", -1.0, 1.0, "lin"),
    ("damp_q", 0.5, 5.0, "log"),
]
GOALS = {"rms": 150e-9, "median": 100e-9, "max": 300e-9, "path": 200e-9, "powerup": 250e-9}
# Hard constraints every trial must meet (else it is not kept): a move inside the PE's stroke only
# scans (no step, max error <= 30 nm), as tests/motion/tracking_controller_test.cc asserts.
AT_REST_SCAN = ["control", "trajectory", "--profile", "trapezoid", "--distance", "4e-7", "--velocity", "2e-4"]
AT_REST_MAX_M = 30e-9


def excess(value, goal):
    return max(0.0, value / goal - 1.0)


def cost_of(result):
    cases = result["cases"]
    s = result["summary"]
    rms = [c["rms_error_m"] for c in cases]
    cost = sum(rms) / len(rms) / 100e-9
    for c in cases:
        cost += 4.0 * excess(c["rms_error_m"], GOALS["rms"])
        cost += 4.0 * excess(c["max_error_m"], GOALS["max"])
        if "path_deviation_m" in c:
            cost += 4.0 * excess(c["path_deviation_m"], GOALS["path"])
    cost += 4.0 * excess(s["worst_powerup_backward_m"], GOALS["powerup"])
    cost += 4.0 * excess(s["median_rms_m"], GOALS["median"])
    cost += s["worst_rms_m"] / GOALS["rms"] + s["worst_max_m"] / GOALS["max"]
    return cost


def write_params(path, values, fixed):
    # JSON is YAML: `--params` reads it as the `tracking:` section.
    with open(path + ".tmp", "w") as f:
        json.dump({"tracking": {**values, **fixed}}, f, indent=1)
    os.replace(path + ".tmp", path)


def run(cli, params_file, cases):
    cmd = [cli, "control", "validate", "--set", "tuning", "--params", params_file, "--json"]
    if cases is not None:
        cmd += ["--cases", str(cases)]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def at_rest_scan_violation(cli, params_file):
    """0 when a 400 nm move only scans within AT_REST_MAX_M; otherwise how far it misses."""
    out = subprocess.run([cli, *AT_REST_SCAN, "--params", params_file, "--json"], check=True,
                         capture_output=True, text=True).stdout
    r = json.loads(out)
    return excess(r["max_error_m"], AT_REST_MAX_M) + float(r["steps"])


def perturb(rng, values, scale, searched):
    new = dict(values)
    for key, lo, hi, kind in rng.sample(searched, rng.randint(1, min(4, len(searched)))):
        v = new[key]
        if kind == "log":
            v *= math.exp(rng.gauss(0.0, scale))
        else:
            v += rng.gauss(0.0, scale) * (hi - lo)
        new[key] = float(f"{min(hi, max(lo, v)):.4g}")
    # Consistency the controller requires.
    new["settle_s"] = min(new["settle_s"], 0.95 * new["catchup_s"])
    new["sprint_low_V"] = min(new["sprint_low_V"], new["low_V"])
    new["unload_V"] = min(new["unload_V"], 100.0 - new["low_V"] - 10.0)
    return new


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", required=True, help="the microcobot binary")
    ap.add_argument("--trials", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scale", type=float, default=0.25, help="std of the log-normal steps")
    ap.add_argument("--start", help="JSON/YAML-as-JSON file of tracking values to start from "
                    "(default: the binary's defaults, `control params --json`)")
    ap.add_argument("--cases", type=int, help="random tuning cases (default: the set's 32)")
    ap.add_argument("--out", required=True, help="directory for trials.jsonl and best.yaml")
    ap.add_argument("--freeze", default="", help="comma-separated keys kept at their start values")
    ap.add_argument("--fixed", default="", help="comma-separated KEY=VALUE tracking values written into "
                    "every trial and never searched (e.g. edge_split_s=305e-6: a design tried with the "
                    "searched gains retuned around it)")
    a = ap.parse_args()
    frozen = {k for k in a.freeze.split(",") if k}
    unknown = frozen - {k for k, *_ in SEARCHED}
    if unknown:
        ap.error(f"--freeze: unknown key(s) {sorted(unknown)}")
    searched = [row for row in SEARCHED if row[0] not in frozen]
    os.makedirs(a.out, exist_ok=True)
    defaults = json.loads(subprocess.run([a.cli, "control", "params", "--json"], check=True,
                                         capture_output=True, text=True).stdout)["tracking"]
    fixed = {}
    for item in (i for i in a.fixed.split(",") if i):
        key, _, value = item.partition("=")
        if key not in defaults or key in {k for k, *_ in SEARCHED}:
            ap.error(f"--fixed: '{key}' is not a tracking value outside the search")
        try:
            fixed[key] = float(value)
        except ValueError:
            ap.error(f"--fixed: {key}={value!r} is not a number")
    start = json.load(open(a.start))["tracking"] if a.start else {}
    best = {k: float(start.get(k, defaults[k])) for k, *_ in SEARCHED}
    rng = random.Random(a.seed)
    trial_file = os.path.join(a.out, "trial.yaml")
    log = open(os.path.join(a.out, "trials.jsonl"), "w")
    write_params(trial_file, best, fixed)
    print(f"start: at-rest scan violation {at_rest_scan_violation(a.cli, trial_file):.3f}", flush=True)
    res = run(a.cli, trial_file, a.cases)
    best_cost = cost_of(res)
    log.write(json.dumps({"trial": 0, "cost": best_cost, "values": best, "summary": res["summary"]}) + "\n")
    log.flush()
    print(f"start cost {best_cost:.3f} {res['summary']}", flush=True)
    write_params(os.path.join(a.out, "best.yaml"), best, fixed)
    for t in range(1, a.trials + 1):
        cand = perturb(rng, best, a.scale, searched)
        write_params(trial_file, cand, fixed)
        try:
            violation = at_rest_scan_violation(a.cli, trial_file)
            if violation > 0:
                log.write(json.dumps({"trial": t, "at_rest_violation": violation, "values": cand}) + "\n")
                continue
            res = run(a.cli, trial_file, a.cases)
        except (subprocess.CalledProcessError, OSError) as e:  # values the controller refuses
            err = getattr(e, "stderr", None) or str(e)
            log.write(json.dumps({"trial": t, "error": err.strip()[:200], "values": cand}) + "\n")
            continue
        c = cost_of(res)
        kept = c < best_cost
        log.write(json.dumps({"trial": t, "cost": c, "kept": kept, "values": cand,
                              "summary": res["summary"]}) + "\n")
        log.flush()
        if kept:
            best, best_cost = cand, c
            write_params(os.path.join(a.out, "best.yaml"), best, fixed)
            s = res["summary"]
            print(f"trial {t}: cost {c:.3f} passed {s['passed']}/{s['cases']} median "
                  f"{s['median_rms_m']*1e9:.0f} worst rms {s['worst_rms_m']*1e9:.0f} max "
                  f"{s['worst_max_m']*1e9:.0f} path {s['worst_path_deviation_m']*1e9:.0f} pu "
                  f"{s['worst_powerup_backward_m']*1e9:.0f}", flush=True)
    print(json.dumps({"best_cost": best_cost, "tracking": {**best, **fixed}}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
