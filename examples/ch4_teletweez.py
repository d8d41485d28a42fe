"""Chapter 4: TéléTweez design calculators (thesis §4.4, appendix B).

The ball screw's efficiencies (eq. B.6, B.9 with errata 5), the axial force of the 2.2 mN m
motor (eq. 4.4), the finger force through the 63 deg transmission (eq. 4.5) against the force the
specification asks (eq. 4.1: 250 N/m over 7 mm), and the magnetic preload (§4.4.2).

    PYTHONPATH=build/release/python /usr/bin/python3 examples/ch4_teletweez.py
"""

import math

from microcobot import tweezers

eff = tweezers.ball_screw_efficiency(diameter_m=4e-3, lead_m=1e-3, mu=0.005)
print(f"ball screw: lead angle {math.degrees(eff['lead_angle_rad']):.2f} deg, "
      f"forward {eff['forward_efficiency']:.3f}, backward {eff['backward_efficiency']:.3f}")
assert eff["backward_efficiency"] < eff["forward_efficiency"] < 1.0

fa = tweezers.axial_force(torque_Nm=2.2e-3, lead_m=1e-3, forward_efficiency=0.89)
print(f"axial force {fa:.1f} N (thesis: 12.3 N)")
assert abs(fa - 12.3) < 0.05

need = tweezers.stiffness_force(stiffness_N_per_m=250.0, opening_m=7e-3)
alpha = math.radians(63.0)
fy = tweezers.finger_force(fa, alpha, eta_t=0.9)
print(f"finger force {fy:.2f} N for a required {need:.2f} N (eq. 4.1); preload > "
      f"{tweezers.min_preload(need, alpha):.2f} N")
assert fy > need
