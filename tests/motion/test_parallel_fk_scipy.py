"""The parallel positioner's kinematics against an independent solver.

The geometry is written here from the dimensions documented in
docs/concepts/parallel-positioner.md (not imported from the program): three legs at 90, 210 and 330
deg; each a two-axis carriage in the base plane (radial axis u, tangential axis w) moving a
spherical joint from b = 40 mm, a rigid leg of L = sqrt((b - r)^2 + h^2), a revolute joint on the
platform at r = 20 mm, o = 8 mm below the top plate, its axis tangential; home: the platform's
joints h = 20 mm above the carriages'. scipy.optimize.least_squares solves the forward kinematics
from the legs' closure equations themselves (|B - P| = L, (B - P) . n = 0), not from the program's
closed-form inverse, for leg coordinates that `microcobot positioner ik --json` gives, and the pose
it finds is compared with the pose asked and with `microcobot positioner fk --json`.
"""

import json
import os
import subprocess

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

CLI = os.environ.get("MC_CLI", "build/release/apps/microcobot/microcobot")

B_RADIUS = 40e-3
P_RADIUS = 20e-3
HEIGHT = 20e-3
TOP = 8e-3
LEG = np.hypot(B_RADIUS - P_RADIUS, HEIGHT)
PHI = np.pi / 2 + np.arange(3) * 2 * np.pi / 3
E_R = np.stack([np.cos(PHI), np.sin(PHI), np.zeros(3)], axis=1)
E_T = np.stack([-np.sin(PHI), np.cos(PHI), np.zeros(3)], axis=1)


def closure(R, d, legs):
    """The six closure residuals [m] of the platform transform (R, d) and the legs' coordinates."""
    res = []
    for i in range(3):
        p = P_RADIUS * E_R[i] - np.array([0.0, 0.0, TOP])
        joint = np.array([0.0, 0.0, HEIGHT + TOP]) + d + R @ p
        axis = R @ E_T[i]
        carriage = (B_RADIUS + legs[2 * i]) * E_R[i] + legs[2 * i + 1] * E_T[i]
        leg = carriage - joint
        res += [np.linalg.norm(leg) - LEG, leg @ axis]
    return np.array(res)


def rotation(angles, convention):
    # SmarPod: R = Rz Ry Rx (extrinsic x, y, z); PI: U -> V -> W about moving axes (intrinsic X, Y, Z).
    return Rotation.from_euler("xyz" if convention == "smarpod" else "XYZ", angles).as_matrix()


def solve_fk(legs, convention="smarpod", pivot=np.zeros(3)):
    """The pose (translation about a moving pivot, angles) whose closure residuals vanish."""
    def f(x):
        R = rotation(x[3:], convention)
        return closure(R, x[:3] + pivot - R @ pivot, legs)

    sol = least_squares(f, np.zeros(6), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-14, sol
    return sol.x


def cli(*args):
    return subprocess.run([CLI, "positioner", *args], capture_output=True, text=True)


def cli_json(*args):
    r = cli(*args, "--json")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def numbers(v):
    return ",".join(repr(float(x)) for x in v)


def reachable_poses(n, seed, convention="smarpod", pivot=None):
    rng = np.random.default_rng(seed)
    extra = ["--convention", convention] + (["--pivot", numbers(pivot)] if pivot is not None else [])
    found = []
    while len(found) < n:
        pose = np.concatenate([rng.uniform(-3e-3, 3e-3, 3), rng.uniform(-0.1, 0.1, 3)])
        r = cli("ik", "--pose", numbers(pose), "--json", *extra)
        if r.returncode == 3:  # outside the workspace: drawn again
            continue
        assert r.returncode == 0, r.stderr
        found.append((pose, np.array(json.loads(r.stdout)["legs_m"])))
    return found


def test_scipy_solves_the_pose_back_from_the_programs_leg_coordinates():
    for pose, legs in reachable_poses(8, 20261206):
        x = solve_fk(legs)
        np.testing.assert_allclose(x[:3], pose[:3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(x[3:], pose[3:], rtol=0, atol=1e-11)


def test_the_programs_forward_kinematics_agrees_with_scipys():
    for pose, legs in reachable_poses(5, 7):
        x = solve_fk(legs)
        fk = cli_json("fk", "--legs", numbers(legs))["pose"]
        got = np.array([fk[k] for k in ("x", "y", "z", "rx", "ry", "rz")])
        np.testing.assert_allclose(got[:3], x[:3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(got[3:], x[3:], rtol=0, atol=1e-11)


def test_pi_poses_and_a_pivot_above_the_plate_agree_with_scipy():
    pivot = np.array([1e-3, -2e-3, 10e-3])
    for pose, legs in reachable_poses(4, 11, convention="pi", pivot=pivot):
        x = solve_fk(legs, convention="pi", pivot=pivot)
        np.testing.assert_allclose(x[:3], pose[:3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(x[3:], pose[3:], rtol=0, atol=1e-11)


def test_an_unreachable_pose_is_one_line_and_exit_3():
    r = cli("ik", "--pose", "0.009,0,0,0,0,0")
    assert r.returncode == 3
    assert r.stdout == ""
    assert r.stderr.count("\n") == 1 and "unreachable: stroke limit" in r.stderr, r.stderr


def test_workspace_slices_through_every_reason_are_written_as_csv(tmp_path):
    # Lifting the platform up to 12 mm passes the stroke limits and, beyond the lift at which the
    # legs stand vertical (8.28 mm), their reach; a fine slice about that lift finds the singular
    # band just below it. Every row is written, finite, and counted in the summary.
    lift = LEG - HEIGHT
    seen = set()
    for name, range_a in (("wide", "-0.012,0.012"), ("fine", f"{lift - 3e-4!r},{lift + 3e-4!r}")):
        out = tmp_path / name
        j = cli_json("workspace", "--slice", "z,rz", "--range-a", range_a, "--range-b", "-0.01,0.01",
                     "--points", "61", "--out", str(out))
        rows = np.genfromtxt(out / "workspace_slice.csv", delimiter=",", names=True)
        assert len(rows) == 61 * 61 == j["slice"]["points"]
        assert np.all(np.isfinite(rows["conditioning"]))
        assert np.all(rows["reach"][rows["z_m"] > lift + 1e-9] == 2)  # out of reach above the vertical legs
        assert np.all(rows["conditioning"][rows["reach"] == 3] < 0.02)
        assert j["slice"]["reachable"] == int(np.sum(rows["reach"] == 0))
        seen |= set(np.unique(rows["reach"]).astype(int))
    assert seen == {0, 2, 3, 4}  # reachable, out of reach, singular, stroke limit


if __name__ == "__main__":
    raise SystemExit(pytest.main([__file__, "-q"]))
