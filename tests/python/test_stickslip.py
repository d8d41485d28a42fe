"""microcobot.stickslip: parameters, simulate, rollout and the error contract."""

import copy
import csv
import os

import numpy as np
import pytest

import microcobot
from microcobot import stickslip as ss

from conftest import cli_error


def read_csv(path):
    with open(path) as f:
        rows = [r for r in csv.reader(l for l in f if not l.startswith("#"))]
    return {name: np.array([float(r[i]) for r in rows[1:]]) for i, name in enumerate(rows[0])}


# ---- parameters ---------------------------------------------------------------------------------


def test_params_round_trip_through_dict_and_yaml(tmp_path, cli):
    p = ss.params()
    assert set(p) == {"pe", "hysteresis", "friction", "slider", "breakaway", "drive", "integrator"}
    # The same keys and values the CLI prints.
    import json

    rc, out, _ = cli("stickslip", "params", "--json")
    assert rc == 0
    assert json.loads(out) == p
    # dict -> params -> dict is the identity, and a changed value is taken.
    assert ss.params(p) == p
    q = copy.deepcopy(p)
    q["slider"]["mass_kg"] = 0.03
    assert ss.params(q)["slider"]["mass_kg"] == 0.03
    # A partial dict overrides only its keys.
    assert ss.params({"slider": {"mass_kg": 0.03}}) == ss.params(q)
    # YAML file written by save_params reads back equal, through the module and through the CLI.
    f = tmp_path / "p.yaml"
    ss.save_params(q, f)
    assert ss.params(f) == ss.params(q)
    assert ss.params(str(f)) == ss.params(q)
    rc, out, _ = cli("stickslip", "params", "--json", "--params", f)
    assert rc == 0 and json.loads(out) == ss.params(q)
    # numpy values are taken as the numbers they hold.
    assert ss.params({"slider": {"mass_kg": np.float64(0.03)}})["slider"]["mass_kg"] == 0.03


def test_invalid_parameter_is_value_error_with_the_cli_message(tmp_path, cli):
    bad = tmp_path / "bad.yaml"
    bad.write_text("slider:\n  mass_kg: -1\n")
    with pytest.raises(ValueError) as e:
        ss.params(bad)
    rc, _, err = cli("stickslip", "params", "--params", bad)
    assert rc == 3
    assert str(e.value) == cli_error(err)
    assert "slider.mass_kg" in str(e.value) and "\n" not in str(e.value)
    # The same from a dict.
    with pytest.raises(ValueError, match=r"^invalid parameter slider\.mass_kg: must be "):
        ss.params({"slider": {"mass_kg": -1.0}})
    # An unknown key and a wrong type are named.
    with pytest.raises(ValueError, match="mass_kgg"):
        ss.params({"slider": {"mass_kgg": 1.0}})
    with pytest.raises(ValueError, match="mass_kg"):
        ss.params({"slider": {"mass_kg": "heavy"}})
    with pytest.raises(ValueError, match="parameters must be a dict"):
        ss.params(3.0)


# ---- simulate -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "wave,amplitude,frequency,direction,duration",
    [
        ("sawtooth", 60.0, 500.0, "forward", 0.02),
        ("sawtooth", 60.0, 500.0, "backward", 0.02),
        ("sine", 40.0, 50.0, "forward", 0.02),
        ("step", 40.0, 50.0, "forward", 0.005),
    ],
)
def test_simulate_equals_the_cli_run(tmp_path, cli, wave, amplitude, frequency, direction, duration):
    r = ss.simulate(wave=wave, amplitude_V=amplitude, frequency_Hz=frequency, direction=direction,
                    duration_s=duration)
    assert set(r) == {"t_s", "u_V", "x1_m", "x2_m"}
    n = len(r["t_s"])
    assert all(isinstance(v, np.ndarray) and v.shape == (n,) and v.dtype == np.float64 for v in r.values())
    assert n == round(duration / 1e-5) + 1
    rc, _, err = cli("stickslip", "simulate", "--wave", wave, "--amplitude", amplitude, "--frequency", frequency,
                     "--direction", direction, "--duration", duration, "--out", tmp_path / "o")
    assert rc == 0, err
    c = read_csv(tmp_path / "o" / "trajectory.csv")
    for k in r:
        np.testing.assert_array_equal(r[k], c[k])  # the same library call, to the last bit
    assert np.all(np.isfinite(r["x2_m"]))
    assert r["u_V"].min() >= 0.0 and r["u_V"].max() <= amplitude + 1e-9


def test_simulate_physics_stepping_direction_and_step_response():
    fwd = ss.simulate(amplitude_V=60.0, frequency_Hz=500.0, direction="forward", duration_s=0.02)
    bwd = ss.simulate(amplitude_V=60.0, frequency_Hz=500.0, direction="backward", duration_s=0.02)
    # Stepping mode (thesis Fig. 2.15-2.16): the slider walks in the commanded direction, several
    # steps of ~ the PE stroke each (g * 60 V ~ 0.1-0.6 um per period, 10 periods).
    assert fwd["x2_m"][-1] - fwd["x2_m"][0] > 0.5e-6
    assert bwd["x2_m"][-1] - bwd["x2_m"][0] < -0.5e-6
    # A 20 V sawtooth scans (Fig. 2.14): the slider follows the PE within each period, and the mean
    # position over the last period differs from the first one's by a small part of the PE stroke
    # (stepping at 60 V moves > 2 strokes in 4 periods).
    scan = ss.simulate(amplitude_V=20.0, frequency_Hz=100.0, duration_s=0.05)
    stroke = np.ptp(scan["x1_m"])
    per = 1000  # samples per 10 ms period
    net = scan["x2_m"][-per - 1:-1].mean() - scan["x2_m"][:per].mean()
    assert np.ptp(scan["x2_m"]) > 0.8 * stroke and abs(net) < 0.1 * stroke
    # A 40 V step moves the PE to a static displacement of the order of g * 40 V (eq. 2.5: g H(U));
    # 5 ms after it the contact modes (595, 1633 Hz) ring at the percent level only.
    g = ss.params()["pe"]["static_gain_m_V"]
    st = ss.simulate(wave="step", amplitude_V=40.0, duration_s=0.005)
    assert st["u_V"][-1] == pytest.approx(40.0)
    tail = st["x1_m"][-100:]
    assert 0.5 * g * 40.0 < tail.mean() < 1.5 * g * 40.0
    assert np.ptp(tail) < 0.02 * tail.mean() < np.ptp(st["x1_m"])


def test_simulate_bad_input_raises_value_error():
    with pytest.raises(ValueError, match="wave"):
        ss.simulate(wave="square")
    with pytest.raises(ValueError, match="direction"):
        ss.simulate(direction="sideways")
    with pytest.raises(ValueError, match="duration_s"):
        ss.simulate(duration_s=-1.0)
    with pytest.raises(ValueError, match="duration_s"):
        ss.simulate(duration_s=1e6)  # over the recorded-samples budget, refused before allocating
    with pytest.raises(ValueError):
        ss.simulate(amplitude_V=150.0)  # beyond the amplifier's 100 V


def test_experiment_threshold_and_steps():
    r = ss.experiment("actuator-step")
    # Thesis Fig. 2.11: the two contact modes near 595 and 1633 Hz.
    assert r["peaks_Hz"] == pytest.approx([595.0, 1633.0], rel=0.05)
    with pytest.raises(ValueError, match="unknown experiment"):
        ss.experiment("nope")


# ---- Actuator and rollout -----------------------------------------------------------------------


def sawtooth_samples(n_axes, steps, amplitude=60.0, frequency=500.0, dt=1e-5):
    """Forward sawtooth samples (slow rise, 60 us edge at 1 V/us) per model step."""
    t = np.arange(1, steps + 1) * dt
    phase = (t * frequency) % 1.0
    edge = amplitude / 1e6 * frequency  # fraction of a period the drop lasts
    rise = 1.0 - edge
    u = np.where(phase < rise, amplitude * phase / rise, amplitude * (1.0 - (phase - rise) / edge))
    return np.tile(u, (n_axes, 1))


def test_rollout_equals_python_stepping_and_is_thread_independent():
    a = ss.Actuator()
    v = sawtooth_samples(3, 2000)
    v[1] *= 0.7  # axes differ
    v[2] = v[2][::-1].copy()
    x0 = np.array([0.0, 1e-3, -2e-3])
    r1 = ss.rollout(a, x0, v, threads=1, operating_point=(60.0, 500.0, "forward"))
    r2 = ss.rollout(a, x0, v, threads=2, operating_point=(60.0, 500.0, "forward"))
    np.testing.assert_array_equal(r1["x2_m"], r2["x2_m"])
    np.testing.assert_array_equal(r1["x1_m"], r2["x1_m"])
    assert r1["x2_m"].shape == (3, 2000) and r1["t_s"][-1] == pytest.approx(2000 * a.dt_s)
    # The same axis stepped one call at a time from Python gives the same numbers.
    for i in range(3):
        s = a.initial_state(slider_position_m=x0[i])
        a.set_operating_point(s, 60.0, 500.0, "forward")
        xs = []
        for u in v[i]:
            a.step(s, u)
            xs.append(a.slider_position(s))
        np.testing.assert_array_equal(np.array(xs), r1["x2_m"][i])
        assert r1["states"][i].t_s == pytest.approx(s.t_s)
    # Continuing from the returned states equals one longer rollout.
    first = ss.rollout(a, x0, v[:, :1000], operating_point=(60.0, 500.0, "forward"))
    second = ss.rollout(a, first["states"], v[:, 1000:])
    np.testing.assert_array_equal(second["x2_m"], r1["x2_m"][:, 1000:])


def test_rollout_physics_translation_invariance():
    # Away from the end stops the dynamics do not depend on where the slider starts: the same drive
    # from different positions gives the same displacement (the model has no position dependence).
    a = ss.Actuator()
    n = 8
    v = sawtooth_samples(n, 4000)
    x0 = np.linspace(-3e-3, 3e-3, n)
    r = ss.rollout(a, x0, v, threads=2, operating_point=(60.0, 500.0, "forward"))
    d = r["x2_m"] - x0[:, None]
    assert d[0, -1] > 0.5e-6  # it steps forward
    np.testing.assert_allclose(d, np.tile(d[0], (n, 1)), rtol=0, atol=1e-12)


def test_rollout_writes_into_a_caller_owned_array():
    a = ss.Actuator()
    v = sawtooth_samples(2, 100)
    out = np.full((2, 100), -1.0)
    out_x1 = np.full((2, 100), -1.0)
    r = ss.rollout(a, None, v, out=out, out_x1=out_x1)
    assert r["x2_m"] is out and r["x1_m"] is out_x1
    assert np.all(out != -1.0) and np.all(out_x1 != -1.0)
    fresh = ss.rollout(a, None, v)
    np.testing.assert_array_equal(fresh["x2_m"], out)
    np.testing.assert_array_equal(fresh["x1_m"], out_x1)


def test_rollout_validates_its_inputs():
    a = ss.Actuator()
    v = sawtooth_samples(2, 100)
    with pytest.raises(ValueError, match="voltages: expected a 2-D array"):
        ss.rollout(a, None, v[0])
    bad = v.copy()
    bad[1, 7] = np.nan
    with pytest.raises(ValueError, match=r"voltages: non-finite value nan at flat index 107"):
        ss.rollout(a, None, bad)
    with pytest.raises(ValueError, match="initial_states: expected 2 slider positions"):
        ss.rollout(a, np.zeros(3), v)
    with pytest.raises(ValueError, match="outside the end stops"):
        ss.rollout(a, np.array([0.0, 1.0]), v)
    with pytest.raises(ValueError, match="out: expected"):
        ss.rollout(a, None, v, out=np.zeros((2, 99)))
    with pytest.raises(ValueError, match="out_x1: expected a writeable"):
        ss.rollout(a, None, v, out_x1=np.zeros((2, 100), order="F"))
    with pytest.raises(ValueError, match="out_x1: expected a float64"):
        ss.rollout(a, None, v, out_x1=np.zeros((2, 100), dtype=np.float32))
    same = np.zeros((2, 100))
    with pytest.raises(ValueError, match="out_x1: must not share memory with out"):
        ss.rollout(a, None, v, out=same, out_x1=same)
    with pytest.raises(ValueError, match="out_x1: must not share memory with out"):
        ss.rollout(a, None, v, out=same, out_x1=same[:])
    with pytest.raises(ValueError, match="threads"):
        ss.rollout(a, None, v, threads=-1)


def test_state_is_plain_copyable_data():
    a = ss.Actuator()
    s = a.initial_state()
    c = copy.copy(s)
    a.step(s, 10.0)
    assert c.t_s == 0.0 and s.t_s == pytest.approx(a.dt_s)
    assert c.u_V == 0.0 and s.u_V == 10.0
    with pytest.raises(ValueError, match="u_V"):
        a.step(s, float("inf"))


def test_computation_failed_is_a_registered_exception():
    assert issubclass(microcobot.ComputationFailed, RuntimeError)
    assert not issubclass(microcobot.ComputationFailed, ValueError)


def test_failed_computation_raises_computation_failed_with_the_cli_message(tmp_path, cli):
    # A sine drive with a slider that never moves: the PI fit has zero gain (a degenerate fit),
    # which the library reports as a failed computation (CLI exit 4).
    t = np.arange(3000) / 25000.0
    u = 20.0 + 20.0 * np.sin(2 * np.pi * 50.0 * t)
    x = np.zeros_like(t)
    with pytest.raises(microcobot.ComputationFailed):
        microcobot.identify.hysteresis(t, u, x)
    f = tmp_path / "flat.csv"
    f.write_text("t_s,u_V,x_m\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(t, u, x)))
    with pytest.raises(microcobot.ComputationFailed) as e:
        microcobot.identify.hysteresis(f)
    rc, _, err = cli("identify", "hysteresis", "--in", f)
    assert rc == 4
    assert str(e.value) == cli_error(err)


def test_rollout_releases_the_gil():
    # While a rollout runs in another thread, this thread keeps running Python code: the longest
    # pause between its iterations stays well below the rollout's duration (it would span the
    # whole call if the GIL were held).
    import threading
    import time

    a = ss.Actuator()
    v = sawtooth_samples(32, 10000)
    done = threading.Event()
    span = []

    def run():
        t0 = time.perf_counter()
        ss.rollout(a, None, v, threads=1, operating_point=(60.0, 500.0, "forward"))
        span.append(time.perf_counter() - t0)
        done.set()

    th = threading.Thread(target=run)
    last, gap = time.perf_counter(), 0.0
    th.start()
    while not done.is_set():
        now = time.perf_counter()
        gap = max(gap, now - last)
        last = now
    th.join()
    assert span[0] > 0.05  # long enough to see
    assert gap < 0.5 * span[0], (gap, span[0])


def test_identification_inputs_are_checked():
    t = np.arange(100) / 25000.0
    with pytest.raises(ValueError, match=r"t, u and x must have the same length \(got 100, 99, 100\)"):
        microcobot.identify.record(t, np.zeros(99), np.zeros(100))
    with pytest.raises(ValueError, match=r"record\.x: non-finite value nan at flat index 5"):
        microcobot.identify.record(t, np.zeros(100), np.r_[np.zeros(5), np.nan, np.zeros(94)])
    r = microcobot.identify.record(t, np.zeros(100), np.ones(100))
    np.testing.assert_array_equal(r["t_s"], t)
    with pytest.raises(ValueError, match="operating_point"):
        ss.rollout(ss.Actuator(), None, np.zeros((1, 10)), operating_point=(60.0, "fast"))
