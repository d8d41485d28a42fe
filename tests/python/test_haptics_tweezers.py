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
    # Eq. B.6 and B.9 (erratum 5 in docs/errata.md: tan(theta - phi) / tan(theta)), against the closed forms.
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


def test_identification_and_evaluation_of_the_dual_stage_interface():
    idr = haptics.identify()
    # Eq. 3.5: below its first mode the Pantograph is a mass, G_0^LF = 1 / M_total.
    assert idr["lf_gain_m_s2_per_N"] * idr["total_mass_kg"] == pytest.approx(1.0, abs=0.05)
    assert idr["cutoff_Hz"] == 200.0  # §3.4.2's crossover
    assert 1.5e-4 < idr["hf_delay_s"] < 1e-3
    assert idr["pipeline"]["lf_gain_m_s2_per_N"] == idr["lf_gain_m_s2_per_N"]
    assert len(idr["lf"]["f_Hz"]) == len(idr["lf"]["h"]) == len(idr["lf"]["coherence"])
    ev = haptics.evaluate(pipeline=idr["pipeline"])
    # Fig. 3.13: both channels together render flatter than the Pantograph alone, which falls away
    # by more than 6 dB above its first mode.
    pant = np.asarray(ev["pantograph_dB"])
    assert ev["flatness_dB"] < np.ptp(pant)
    assert np.max(np.abs(pant[np.asarray(ev["fc_Hz"]) > 250.0])) > 6.0
    # Without an explicit pipeline, evaluate identifies one first: the same numbers.
    assert haptics.evaluate()["flatness_dB"] == ev["flatness_dB"]


def test_teletweez_bandwidth_identification_reproduces_fig_4_25():
    r = tweezers.identify_bandwidth()
    # Thesis Fig. 4.25: the dominant mode near 150 Hz, the antiresonance near 390 Hz, a flat band of
    # at least 100 Hz below the mode.
    assert r["mode_Hz"] == pytest.approx(150.0, abs=10.0)
    assert r["antiresonance_Hz"] == pytest.approx(390.0, abs=20.0)
    assert 100.0 <= r["bandwidth_Hz"] < r["mode_Hz"]
    # The H1 estimate agrees with the model's analytic response where the coherence is high (1 dB).
    f, c = r["f_Hz"], r["coherence"]
    sel = (f > 20) & (f < 1000) & (c > 0.95)
    assert sel.sum() > 500
    np.testing.assert_allclose(20 * np.log10(r["magnitude"][sel] / r["model_magnitude"][sel]), 0.0, atol=1.0)
    with pytest.raises(ValueError, match="fs_Hz"):
        tweezers.identify_bandwidth(options={"fs_Hz": -1.0})


def test_a_lead_whose_angle_rounds_to_90_degrees_is_named_as_the_lead():
    # The error named the derived lead_angle_rad, not the lead the caller gave.
    with pytest.raises(ValueError, match="lead_m: too large for diameter_m"):
        tweezers.ball_screw_efficiency(0.006, 1e20, 0.1)
