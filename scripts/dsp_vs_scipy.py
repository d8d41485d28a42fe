#!/usr/bin/env python3
"""Compares the `microcobot dsp` CLI with the scipy reference vectors in tests/data.

Usage: python3 scripts/dsp_vs_scipy.py path/to/microcobot

Needs no numpy or scipy: the references were made by tests/data/gen_reference.py (scipy
1.10.1). Prints, per function, how many cases were compared and the largest deviation; the
figures of docs/concepts/stick-slip.md's signal-toolkit section come from this script.
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "tests", "data")


def cli(binary, *args):
    out = subprocess.run([binary, *map(str, args), "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def fnv1a64(bits):
    """FNV-1a over the sequence as bytes 0/1 (numpy uint8 tobytes(), as gen_reference.py)."""
    h = 0xCBF29CE484222325
    for ch in bits:
        h ^= ch
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def rel_dev(a, b):
    worst = 0.0
    for x, y in zip(a, b):
        scale = max(abs(y), 1e-300)
        worst = max(worst, abs(x - y) / scale)
    return worst


def mls(binary):
    ref = json.load(open(os.path.join(DATA, "dsp_mls.json")))
    same = 0
    for case in ref["cases"]:
        bits = cli(binary, "dsp", "mls", "--bits", case["nbits"])["seq"]
        seq = "".join(str(v) for v in bits)
        ok = len(seq) == case["length"] and seq.count("1") == case["ones"] and fnv1a64(bits) == case["fnv1a64"]
        if "seq" in case:
            ok = ok and seq == case["seq"]
        same += ok
    print(f"mls: {same}/{len(ref['cases'])} sequences identical to scipy.signal.max_len_seq "
          f"(nbits {ref['cases'][0]['nbits']}..{ref['cases'][-1]['nbits']})")


def butter(binary):
    ref = json.load(open(os.path.join(DATA, "dsp_butter.json")))
    worst, n = 0.0, 0
    for case in ref["cases"]:
        if case["kind"] == "lr" and case["order"] != 4:
            continue  # the CLI designs LR4 only
        kind = case["type"] if case["kind"] == "butter" else "lr4-" + case["type"]
        sos = cli(binary, "dsp", "butter", "--order", case["order"], "--fc", case["fc"], "--fs", case["fs"],
                  "--type", kind)["sos"]
        flat = [v for row in sos for v in row]
        want = [v for row in case["sos"] for v in row]
        if len(flat) != len(want):
            raise SystemExit(f"butter: section count differs for {case}")
        # Relative to the largest coefficient of the section (zeros stay zeros).
        for got_row, want_row in zip(sos, case["sos"]):
            scale = max(abs(v) for v in want_row)
            worst = max(worst, max(abs(g - w) / scale for g, w in zip(got_row, want_row)))
        n += 1
    print(f"butter/lr4: {n} designs, largest coefficient deviation {worst:.2e} (relative to the section)")


def welch(binary):
    ref = json.load(open(os.path.join(DATA, "dsp_welch.json")))
    worst, n = 0.0, 0
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "x.csv")
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["x"])
            for v in ref["x"]:
                w.writerow([repr(v)])
        for case in ref["cases"]:
            opt = case["options"]
            args = ["dsp", "welch", "--in", path, "--column", "x", "--fs", opt["fs"]]
            for key in ("nperseg", "noverlap", "nfft", "detrend", "scaling"):
                if key in opt:
                    args += ["--" + key, opt[key]]
            got = cli(binary, *args)
            if len(got["psd"]) != len(case["pxx"]):
                raise SystemExit(f"welch: length differs for {opt}")
            worst = max(worst, rel_dev(got["psd"], case["pxx"]), rel_dev(got["f_Hz"], case["f"]))
            n += 1
    print(f"welch: {n} option sets, largest relative deviation of f and Pxx {worst:.2e}")


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    mls(sys.argv[1])
    butter(sys.argv[1])
    welch(sys.argv[1])


if __name__ == "__main__":
    main()
