"""Chapter 2: the stick-slip actuator model and its identification, from Python.

Simulates the thesis's identification experiments on the model (a 40 V step sampled at 25 kHz,
Fig. 2.11; a 40 V / 50 Hz sine, Fig. 2.12), identifies the asperity modes (eq. 2.20-2.21) and the
Prandtl-Ishlinskii hysteresis (eq. 2.5) from those arrays, then runs 16 axes at once with rollout.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/ch2_stickslip_identification.py
"""

import numpy as np

from microcobot import identify, stickslip

params = stickslip.params()

# Step 1b (thesis §2.5.2.1): a 40 V step in scanning mode, recorded at 25 kHz (every 4th 10 us step).
step = stickslip.simulate(params, wave="step", amplitude_V=40.0, duration_s=0.03, record_every=4)
fm = identify.friction_modes(step["t_s"], step["u_V"], step["x2_m"], params=params)
print(f"asperity modes: {fm['mode_a']['frequency_Hz']:.0f} Hz and {fm['mode_b']['frequency_Hz']:.0f} Hz "
      f"(thesis: 595 and 1633 Hz)")
assert abs(fm["mode_a"]["frequency_Hz"] - 595) < 0.05 * 595 and abs(fm["mode_b"]["frequency_Hz"] - 1633) < 0.05 * 1633

# Step 2 (thesis §2.5.2.2): the PI hysteresis from a 40 V / 50 Hz sine.
sine = stickslip.simulate(params, wave="sine", amplitude_V=40.0, frequency_Hz=50.0, duration_s=0.06, record_every=4)
hy = identify.hysteresis(sine["t_s"], sine["u_V"], sine["x2_m"], operators=35)
print(f"PI model: g = {hy['static_gain_m_V']:.3e} m/V, loop RMS error {100 * hy['rms_fraction']:.2f} % of the stroke")
assert hy["rms_fraction"] < 0.05

# Stepping mode on 16 axes at once (thesis Fig. 2.15): 60 V sawtooth at 500 Hz, amplitudes 40-60 V.
dt = stickslip.Actuator(params).dt_s
t = np.arange(1, 2001) * dt
phase = (t * 500.0) % 1.0
edge = 60.0 / 1e6 * 500.0
shape = np.where(phase < 1 - edge, phase / (1 - edge), 1 - (phase - (1 - edge)) / edge)
amplitudes = np.linspace(40.0, 60.0, 16)
r = stickslip.rollout(params, None, amplitudes[:, None] * shape, threads=2, operating_point=(60.0, 500.0, "forward"))
travel = r["x2_m"][:, -1] - r["x2_m"][:, 0]
for a, d in zip(amplitudes[::5], travel[::5]):
    print(f"  {a:5.1f} V: {1e6 * d:6.3f} um in {t[-1] * 1e3:.0f} ms")
assert travel[-1] > travel[0]  # a larger amplitude steps further
