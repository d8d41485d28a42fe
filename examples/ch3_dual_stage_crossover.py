"""Chapter 3: the dual-stage haptic interface's Linkwitz-Riley crossover and rendering pipeline.

Designs the LR4 crossover at 200 Hz (thesis §3.3, Fig. 3.8), checks that the two bands sum to an
all-pass, renders a PRBS force through the pipeline (Pantograph low band, Haptuator high band) and
identifies the low band's response from the data with Welch's H1 estimate and a rational fit.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/ch3_dual_stage_crossover.py
"""

import numpy as np

from microcobot import dsp, haptics

fs, fc = 10000.0, 200.0
low, high = dsp.crossover(4, fc, fs=fs)
f = np.geomspace(1.0, 4000.0, 400)
_, hl = dsp.sosfreqz(low, worN=f, fs=fs)
_, hh = dsp.sosfreqz(high, worN=f, fs=fs)
print(f"LR4 at {fc:.0f} Hz: max ||L + H| - 1| = {np.max(np.abs(np.abs(hl + hh) - 1)):.2e} (all-pass)")
assert np.allclose(np.abs(hl + hh), 1.0, atol=1e-9)

# The rendering pipeline on a +-20 mN PRBS force (thesis §3.4's identification input), per block;
# C_HF amplifies the high band, so larger forces would saturate the Haptuator's 30 V.
force = dsp.prbs(12, 40000, clock_divider=1, amplitude=0.02)
pipe = haptics.RenderPipeline()
out = pipe.process(force)
print(f"Pantograph force {np.ptp(out['f_m_N']):.2f} N p-p, Haptuator {np.ptp(out['u_V']):.2f} V p-p")

# H1 estimate of force -> Pantograph command, and a 4th-order fit: the LR4 low-pass times C_LF.
fr, h, coh = dsp.tfestimate(force, out["f_m_N"], fs=fs, nperseg=2048)
band = (fr > 5) & (fr < 1000)
fit = dsp.tffit(fr[band], h[band], nz=0, np=4)
print(f"fitted poles (Hz): {np.round(np.abs(fit['poles']) / 2 / np.pi, 1)}; relative RMS error {fit['relative_rms_error']:.2e}")
assert fit["relative_rms_error"] < 0.05
# The LR4 low band's poles are two Butterworth pairs at fc: the fitted pole magnitudes centre on fc.
assert abs(np.exp(np.mean(np.log(np.abs(fit["poles"])))) / (2 * np.pi) - fc) < 0.05 * fc
assert np.max(np.abs(out["u_V"])) < pipe.params["max_voltage_V"]  # the Haptuator stays out of saturation
