"""microcobot.control: controllers stepped from Python equal the library's closed loop; closed-loop
runs reach their references (thesis §2.7)."""

import numpy as np
import pytest

from microcobot import control, stickslip


@pytest.fixture(scope="module")
def plant():
    return control.Plant()


def test_velocity_controller_stepped_from_python_equals_run_velocity(plant):
    # The loop of motion/closed_loop.cc written in Python with the bound pieces: the same numbers.
    ref, duration = 100e-6, 0.05
    p = plant.params
    model = plant.model
    ctl = control.VelocityController(plant, mode="model")
    ctl.set_reference(ref)
    sensor = control.PositionSensor(p["sensor"])
    s = model.initial_state(slider_position_m=0.0)
    ratio = plant.steps_per_tick(p["velocity"]["control_rate_Hz"])
    tick = ratio * model.dt_s
    per = round(1.0 / p["velocity"]["sawtooth_frequency_Hz"] / tick)
    ticks = round(duration / tick)
    x_prev = model.slider_position(s)
    v, amp = [], []
    for k in range(ticks):
        ctl.update(sensor.measure(model.slider_position(s)))
        model.set_operating_point(s, *ctl.operating_point)
        for _ in range(ratio):
            model.step(s, ctl.next_drive(model.dt_s))
        if (k + 1) % per == 0:
            x = model.slider_position(s)
            v.append((x - x_prev) / (per * tick))
            amp.append(ctl.amplitude_V)
            x_prev = x
    r = control.run_velocity(plant, ref, mode="model", duration_s=duration)
    np.testing.assert_allclose(np.array(v), r["v_m_s"], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(np.array(amp), r["amplitude_V"])


def test_velocity_run_reaches_the_reference(plant):
    r = control.run_velocity(plant, 100e-6, mode="model", duration_s=0.3)
    m = r["metrics"]
    # Model-based velocity control (feedforward from the step map + PID): mean velocity over the
    # second half within 5 % of the reference, settled.
    assert abs(m["steady_state_error_rel"]) < 0.05
    assert m["settled"]
    assert len(r["t_s"]) == len(r["v_m_s"]) == len(r["amplitude_V"])
    back = control.run_velocity(plant, -100e-6, mode="model", duration_s=0.3)
    assert back["metrics"]["mean_velocity_m_s"] < 0


def test_position_run_gets_in_position(plant):
    r = control.run_position(plant, target_m=50e-6)
    m = r["metrics"]
    assert m["in_position"]
    assert m["final_error_m"] < 20e-9
    assert abs(r["x_m"][-1] - 50e-6) < 20e-9


def test_streamed_setpoints_are_followed_closer_than_todays_controller_follows_them(plant):
    # A 20 um ramp at 200 um/s streamed at 1 kHz from Python, then held.
    t = np.arange(0, 0.15, 1e-3)
    setpoints = np.clip(200e-6 * t, 0.0, 20e-6)
    runs = {k: control.run_tracking(plant, setpoints, tracker=k) for k in ("tracking", "hybrid")}
    for k, r in runs.items():
        assert len(r["t_s"]) == len(r["x_m"]) == len(r["ref_m"]) == len(r["u_V"]), k
        assert np.all(np.isfinite(r["x_m"])), k
        assert abs(r["ref_m"][-1] - 20e-6) < 1e-9, "the stream holds the last setpoint"
    tr, hy = runs["tracking"]["metrics"], runs["hybrid"]["metrics"]
    assert tr["rms_error_m"] < 0.5e-6, tr
    assert tr["rms_error_m"] < hy["rms_error_m"], (tr, hy)
    assert tr["final_error_m"] < 5e-9, tr
    assert tr["edges"] > 0, "20 um is many steps"


def test_run_tracking_refuses_bad_input(plant):
    with pytest.raises(ValueError, match="tracker"):
        control.run_tracking(plant, np.zeros(10), tracker="fuzzy")
    with pytest.raises(ValueError, match="setpoints_m"):
        control.run_tracking(plant, np.array([0.0, np.nan]))
    with pytest.raises(ValueError, match=r"setpoints_m\[1\].*stroke"):
        control.run_tracking(plant, np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match="setpoint_rate_Hz"):
        control.run_tracking(plant, np.zeros(10), setpoint_rate_Hz=0.0)
    with pytest.raises(ValueError, match="duration_s"):
        control.run_tracking(plant, np.zeros(10), duration_s=1e9)


def test_position_controller_steppable(plant):
    model = plant.model
    ctl = control.PositionController(plant)
    ctl.set_target(5e-6)
    s = model.initial_state()
    ratio = plant.steps_per_tick(plant.params["position"]["control_rate_Hz"])
    modes = set()
    for _ in range(3000):
        ctl.update(model.slider_position(s))
        model.set_operating_point(s, *ctl.operating_point)
        for _ in range(ratio):
            model.step(s, ctl.next_drive(model.dt_s))
        modes.add(ctl.mode)
    assert ctl.in_position, ctl.mode
    assert abs(model.slider_position(s) - 5e-6) < 20e-9
    assert "hold" in modes


def test_control_errors(plant):
    with pytest.raises(ValueError, match="reference_m_s"):
        control.run_velocity(plant, 0.0)
    with pytest.raises(ValueError, match="start_m"):
        control.run_position(plant, target_m=1e-6, start_m=1.0)
    with pytest.raises(ValueError, match="invalid parameter velocity"):
        control.Plant({"velocity": {"delay_periods": 0}})
    with pytest.raises(ValueError, match="mode"):
        control.VelocityController(plant, mode="fuzzy")
    ctl = control.VelocityController(plant)
    with pytest.raises(ValueError, match="measured_position_m"):
        ctl.update(float("nan"))
