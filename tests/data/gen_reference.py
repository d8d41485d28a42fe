#!/usr/bin/python3
"""Reference vectors for the dsp/ident tests, computed with scipy.

Command (from the repository root, with Debian's python3-scipy 1.10 / python3-numpy 1.24):

    /usr/bin/python3 tests/data/gen_reference.py

Writes tests/data/dsp_*.json. The tests read these files and need no Python. The inputs
are generated here from fixed seeds (numpy's default_rng) and stored in the files too.
"""
import json
import os

import numpy as np
import scipy
import scipy.signal as sig

OUT = os.path.dirname(os.path.abspath(__file__))


def dump(name, obj):
    obj = {"generator": "tests/data/gen_reference.py", "scipy": scipy.__version__,
           "numpy": np.__version__, **obj}
    with open(os.path.join(OUT, name), "w") as f:
        json.dump(obj, f, indent=None, separators=(",", ":"))
        f.write("\n")


def cplx(a):
    a = np.asarray(a)
    return {"re": a.real.tolist(), "im": a.imag.tolist()}


# Butterworth and Linkwitz-Riley second-order sections.
cases = []
for order, fc, fs, btype in [(1, 100.0, 10000.0, "low"), (2, 200.0, 10000.0, "low"),
                             (2, 200.0, 10000.0, "high"), (3, 1000.0, 48000.0, "low"),
                             (4, 50.0, 10000.0, "high"), (5, 3000.0, 10000.0, "low"),
                             (6, 1.0, 10000.0, "low"), (7, 120.0, 1000.0, "high"),
                             (8, 4000.0, 10000.0, "low"), (2, 1.0, 10000.0, "high")]:
    sos = sig.butter(order, fc, btype, fs=fs, output="sos")
    cases.append({"kind": "butter", "order": order, "fc": fc, "fs": fs, "type": btype,
                  "sos": sos.tolist()})
for order, fc, fs, btype in [(4, 200.0, 10000.0, "low"), (4, 200.0, 10000.0, "high"),
                             (2, 500.0, 8000.0, "low"), (2, 500.0, 8000.0, "high"),
                             (4, 1.0, 10000.0, "low")]:
    half = sig.butter(order // 2, fc, btype, fs=fs, output="sos")
    cases.append({"kind": "lr", "order": order, "fc": fc, "fs": fs, "type": btype,
                  "sos": np.vstack([half, half]).tolist()})
dump("dsp_butter.json", {"cases": cases})

# Maximum-length sequences.
def fnv1a64(data):
    h = 0xcbf29ce484222325
    for byte in data:
        h = ((h ^ int(byte)) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return "%016x" % h


mls = []
for n in range(2, 21):
    seq = sig.max_len_seq(n)[0].astype(np.uint8)
    case = {"nbits": n, "length": len(seq), "ones": int(seq.sum()), "fnv1a64": fnv1a64(seq.tobytes())}
    if n <= 14:  # small sequences in full; longer ones by length, weight and 64-bit hash
        case["seq"] = "".join(map(str, seq))
    mls.append(case)
dump("dsp_mls.json", {"cases": mls})

# Welch PSD, CSD and coherence on random signals.
rng = np.random.default_rng(20261122)
x = rng.standard_normal(5000)
b, a = sig.butter(3, 0.2)
y = sig.lfilter(b, a, x) + 0.3 * rng.standard_normal(5000) + 1.5
opts = [dict(fs=1.0), dict(fs=10000.0, nperseg=512), dict(fs=2000.0, nperseg=300, noverlap=100),
        dict(fs=1000.0, nperseg=256, nfft=1000), dict(fs=1000.0, nperseg=255, nfft=255, detrend=False),
        dict(fs=500.0, nperseg=128, scaling="spectrum"), dict(fs=100.0, nperseg=1024, noverlap=1000),
        dict(fs=1.0, nperseg=8000)]
wcases = []
for o in opts:
    f, pxx = sig.welch(x, **o)
    _, pyy = sig.welch(y, **o)
    _, pxy = sig.csd(x, y, **o)
    co = {k: v for k, v in o.items() if k != "scaling"}
    _, cxy = sig.coherence(x, y, **co)
    wcases.append({"options": {k: (v if v is not False else "none") for k, v in o.items()},
                   "f": f.tolist(), "pxx": pxx.tolist(), "pyy": pyy.tolist(), "pxy": cplx(pxy),
                   "cxy": cxy.tolist()})
dump("dsp_welch.json", {"x": x.tolist(), "y": y.tolist(), "cases": wcases})

# Continuous-to-discrete conversions and lsim.
A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-4.559e6 * 50.0, -4.559e6 - 2135.0 * 50.0, -2135.0 - 50.0]])
B = np.array([[0.0], [0.0], [1.0]])
C = np.array([[6.406e5 * 50.0, 250.0 * 50.0 + 6.406e5, 250.0]])
D = np.array([[0.0]])
c2d = []
for method, dt, alpha in [("zoh", 1e-4, None), ("zoh", 1e-3, None), ("bilinear", 1e-4, None),
                          ("bilinear", 1e-3, None)]:
    ad, bd, cd, dd, _ = sig.cont2discrete((A, B, C, D), dt, method=method)
    c2d.append({"method": method, "dt": dt, "Ad": ad.tolist(), "Bd": bd.tolist(), "Cd": cd.tolist(),
                "Dd": dd.tolist()})
num = [250.0, 6.406e5]
den = [1.0, 2135.0, 4.559e6]
t = np.arange(0, 400) * 2.5e-5
u = np.sin(2 * np.pi * 700.0 * t) + 0.5 * np.sign(np.sin(2 * np.pi * 170.0 * t))
_, y_interp, _ = sig.lsim((num, den), u, t, interp=True)
_, y_hold, _ = sig.lsim((num, den), u, t, interp=False)
_, y_step = sig.step((num, den), T=t)
_, y_imp = sig.impulse((num, den), T=t)
Ac, Bc, Cc, Dc = sig.tf2ss(num, den)
w = [10.0, 628.3, 6283.0, 1e5]
_, hw = sig.freqresp((num, den), w)
dump("dsp_lti.json", {"A": A.tolist(), "B": B.tolist(), "C": C.tolist(), "D": D.tolist(), "c2d": c2d,
                      "num": num, "den": den, "t": t.tolist(), "u": u.tolist(),
                      "y_interp": y_interp.tolist(), "y_hold": y_hold.tolist(), "y_step": y_step.tolist(),
                      "y_impulse": y_imp.tolist(),
                      "tf2ss": {"A": Ac.tolist(), "B": Bc.tolist(), "C": Cc.tolist(), "D": Dc.tolist()},
                      "w": w, "h": cplx(hw)})

# Statistics (scipy.stats defaults: biased skewness, Fisher excess kurtosis).
import scipy.stats as st
s = rng.gamma(2.0, 1.5, 1000)
dump("dsp_stats.json", {"x": s.tolist(), "mean": float(np.mean(s)), "std": float(np.std(s)),
                        "rms": float(np.sqrt(np.mean(s ** 2))), "skewness": float(st.skew(s)),
                        "kurtosis": float(st.kurtosis(s))})
