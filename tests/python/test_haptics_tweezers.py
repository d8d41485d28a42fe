"""microcobot.haptics (rendering pipeline per tick and per block) and microcobot.tweezers (design
calculators) against the thesis's figures and closed forms."""

import math

import numpy as np
import pytest

from microcobot import dsp, haptics, tweezers


def test_block_equals_ticks_and_bands_sum_to_allpass():
    force = dsp.prbs(10, 5000, clock_divider=3, amplitude=0.01)
    a, b = haptics.RenderPipeline(), haptics.RenderPipeline()
    block = a.process(force)
    ticks = np.array([b.tick(f) for f in force])
    np.testing.assert_array_equal(block["f_m_N"], ticks[:, 0])
    np.testing.assert_array_equal(block["u_V"], ticks[:, 1])
    # reset() starts over: the same block again gives the same output.
    a.reset()
    np.testing.assert_array_equal(a.process(force)["f_m_N"], block["f_m_N"])
    # The LR4 crossover's two bands sum to an all-pass (thesis §3.3, Fig. 3.8).
    for f in (10.0, 200.0, 1000.0, 3000.0):
        assert abs(a.lowpass_response(f) + a.highpass_response(f)) == pytest.approx(1.0, abs=1e-9)
    # A constant force goes to the Pantograph (low band) only, scaled by C_LF = K_sys / G0_LF = 1.
    c = haptics.RenderPipeline().process(np.full(20000, 0.5))
    assert c["f_m_N"][-1] == pytest.approx(0.5, rel=1e-6)
    assert abs(c["u_V"][-1]) < 1e-6


def test_pipeline_errors():
    with pytest.raises(ValueError, match="cutoff_Hz"):
        haptics.RenderPipeline({"cutoff_Hz": -1.0})
    with pytest.raises(ValueError, match="force_N"):
        haptics.RenderPipeline().process(np.array([0.0, np.inf]))


def test_tweezers_calculators_reproduce_the_thesis():
    # Eq. 4.4: 2.2 mN m, 1 mm lead, eta_f = 0.89 -> 12.3 N.
    assert tweezers.axial_force(2.2e-3, 1e-3, 0.89) == pytest.approx(12.3, abs=0.05)
    # Eq. 4.1: 250 N/m over 7 mm -> 1.75 N; preload for 1.75 N at 63 deg -> 3.85 N (§4.4.2).
    assert tweezers.stiffness_force(250.0, 7e-3) == pytest.approx(1.75)
    assert tweezers.min_preload(1.75, math.radians(63.0)) == pytest.approx(3.85, abs=0.01)
    # Eq. B.6 and B.9 (errata 5: tan(theta - phi) / tan(theta)), against the closed forms.
    d, p, mu = 4e-3, 1e-3, 0.01
    e = tweezers.ball_screw_efficiency(d, p, mu)
    th, phi = math.atan(p / (math.pi * d)), math.atan(mu)
    assert e["lead_angle_rad"] == pytest.approx(th, rel=1e-12)
    assert e["forward_efficiency"] == pytest.approx(math.tan(th) / math.tan(th + phi), rel=1e-12)
    assert e["backward_efficiency"] == pytest.approx(math.tan(th - phi) / math.tan(th), rel=1e-12)
    # Self-locking when the friction angle exceeds the lead angle: nothing transmitted back.
    assert tweezers.ball_screw_efficiency(d, p, 0.2)["backward_efficiency"] == 0.0
    with pytest.raises(ValueError, match="diameter"):
        tweezers.lead_angle(-1.0, 1e-3)
