"""microcobot.positioner: the parallel positioner's kinematics over numpy arrays.

The forward kinematics is compared with an independent solver: scipy.optimize solves the legs' closure
equations written here from the dimensions documented in docs/concepts/parallel-positioner.md (not
imported from the module). The rest checks the module against itself (IK -> FK round trips, the
Jacobian against finite differences of the IK), against the command line (the same library calls)
and its refusals: one-line exceptions naming the row.
"""

import json
import tracemalloc

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from conftest import cli_error
from microcobot import ComputationFailed, positioner

# The documented geometry (docs/concepts/parallel-positioner.md, "Dimensions of a 110.45-size device").
B_RADIUS, P_RADIUS, HEIGHT, TOP, HALF_STROKE = 40e-3, 20e-3, 20e-3, 8e-3, 6e-3
LEG = np.hypot(B_RADIUS - P_RADIUS, HEIGHT)
PHI = np.pi / 2 + np.arange(3) * 2 * np.pi / 3
E_R = np.stack([np.cos(PHI), np.sin(PHI), np.zeros(3)], axis=1)
E_T = np.stack([-np.sin(PHI), np.cos(PHI), np.zeros(3)], axis=1)


def closure(R, d, legs):
    """The six closure residuals [m]: |B - P| = L and (B - P) . n = 0 for each leg."""
    res = []
    for i in range(3):
        joint = np.array([0.0, 0.0, HEIGHT + TOP]) + d + R @ (P_RADIUS * E_R[i] - np.array([0.0, 0.0, TOP]))
        carriage = (B_RADIUS + legs[2 * i]) * E_R[i] + legs[2 * i + 1] * E_T[i]
        leg = carriage - joint
        res += [np.linalg.norm(leg) - LEG, leg @ (R @ E_T[i])]
    return np.array(res)


def scipy_fk(legs):
    """The SmarPod pose (about the top plate's centre) whose closure residuals vanish."""
    def f(x):
        return closure(Rotation.from_euler("xyz", x[3:]).as_matrix(), x[:3], legs)

    sol = least_squares(f, np.zeros(6), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-14, sol
    return sol.x


@pytest.fixture(scope="module")
def pos():
    return positioner.Positioner()


def random_poses(n, seed, mm=3e-3, rad=0.1):
    rng = np.random.default_rng(seed)
    return np.concatenate([rng.uniform(-mm, mm, (n, 3)), rng.uniform(-rad, rad, (n, 3))], axis=1)


def reachable_poses(pos, n, seed, **frame):
    p = random_poses(10 * n, seed)
    p = p[pos.reachable(p, **frame)]
    assert len(p) >= n
    return p[:n]


def one_line(excinfo):
    text = str(excinfo.value)
    assert "\n" not in text, text
    return text


# ---- parameters --------------------------------------------------------------------------------

def test_the_default_geometry_is_the_documented_one_and_the_clis(pos, cli):
    p = positioner.params()
    assert (p["base_radius_m"], p["platform_radius_m"], p["joint_height_m"], p["top_offset_m"]) == (
        B_RADIUS, P_RADIUS, HEIGHT, TOP)
    assert pos.params == p
    assert pos.leg_length_m == pytest.approx(LEG, abs=1e-18)
    assert pos.home_height_m == pytest.approx(HEIGHT + TOP, abs=1e-18)
    code, out, err = cli("positioner", "params", "--json")
    assert code == 0, err
    assert json.loads(out) == p
    # Constructible from the dict it reads as (a partial one overrides its keys only).
    assert positioner.Positioner(p).params == p
    assert positioner.Positioner({"top_offset_m": 10e-3}).home_height_m == pytest.approx(30e-3)


def test_a_bad_key_or_value_is_the_librarys_one_line_error(cli, tmp_path):
    for bad, expected in (({"bogus_m": 1.0}, "unknown key 'bogus_m'"),
                          ({"platform_radius_m": 0.05},
                           "invalid parameter platform_radius_m: must be within [1 mm, base_radius_m)")):
        with pytest.raises(ValueError) as e:
            positioner.Positioner(bad)
        assert expected in one_line(e)
        with pytest.raises(ValueError):
            positioner.params(bad)
        f = tmp_path / "geometry.yaml"
        f.write_text(f"{next(iter(bad))}: {next(iter(bad.values()))}\n")
        code, _, err = cli("positioner", "params", "--params", f)
        assert code == 3 and expected in cli_error(err)


# ---- inverse and forward kinematics --------------------------------------------------------------

def test_ik_then_fk_gives_the_poses_back_over_random_reachable_poses(pos):
    poses = reachable_poses(pos, 300, 20261206)
    back = pos.fk(pos.ik(poses))
    np.testing.assert_allclose(back[:, :3], poses[:, :3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(back[:, 3:], poses[:, 3:], rtol=0, atol=1e-11)


@pytest.mark.parametrize("frame", [dict(convention="pi", pivot=[1e-3, -2e-3, 10e-3]),
                                   dict(convention="smarpod", pivot=[0.0, 0.0, 5e-3], pivot_mode="fixed")])
def test_the_round_trip_holds_in_pis_convention_and_about_a_pivot(pos, frame):
    poses = reachable_poses(pos, 100, 11, **frame)
    back = pos.fk(pos.ik(poses, **frame), **frame)
    np.testing.assert_allclose(back, poses, rtol=0, atol=1e-11)


def test_fk_agrees_with_an_independent_scipy_solve_of_the_closure_equations(pos):
    poses = reachable_poses(pos, 8, 7)
    legs = pos.ik(poses)
    fk = pos.fk(legs)
    for i in range(len(legs)):
        x = scipy_fk(legs[i])
        np.testing.assert_allclose(fk[i, :3], x[:3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(fk[i, 3:], x[3:], rtol=0, atol=1e-11)
        # The module's IK closes the independent equations.
        R = Rotation.from_euler("xyz", poses[i, 3:]).as_matrix()
        assert np.max(np.abs(closure(R, poses[i, :3], legs[i]))) < 1e-15


def test_ik_and_fk_are_the_command_lines(pos, cli):
    pose = np.array([1e-3, -0.5e-3, 0.8e-3, 0.02, -0.03, 0.05])
    code, out, err = cli("positioner", "ik", "--pose", ",".join(map(repr, pose)), "--json")
    assert code == 0, err
    legs = pos.ik(pose)
    assert legs.shape == (6,)
    assert legs.tolist() == json.loads(out)["legs_m"]
    code, out, err = cli("positioner", "fk", "--legs", ",".join(map(repr, legs)), "--json")
    assert code == 0, err
    got = json.loads(out)["pose"]
    assert pos.fk(legs).tolist() == [got[k] for k in ("x", "y", "z", "rx", "ry", "rz")]


def test_a_guess_seeds_newton_per_row_or_for_all(pos):
    poses = reachable_poses(pos, 20, 3)
    legs = pos.ik(poses)
    np.testing.assert_allclose(pos.fk(legs, poses + 1e-5), poses, rtol=0, atol=1e-11)
    np.testing.assert_allclose(pos.fk(legs, np.zeros(6)), poses, rtol=0, atol=1e-11)
    with pytest.raises(ValueError) as e:
        pos.fk(legs, np.zeros((3, 6)))
    assert "guess: expected one pose or one per row of legs (20), got 3" == one_line(e)


# ---- refusals ------------------------------------------------------------------------------------

def test_unreachable_and_non_finite_poses_raise_one_line_naming_the_row(pos):
    poses = np.zeros((4, 6))
    poses[1, 0] = 9e-3
    with pytest.raises(ValueError) as e:
        pos.ik(poses)
    msg = one_line(e)
    assert msg.startswith("poses[1]: pose (9, 0, 0) mm, (0, 0, 0) deg unreachable: stroke limit: leg "), msg
    poses[1, 0] = 0.0
    poses[3, 4] = np.nan
    with pytest.raises(ValueError) as e:
        pos.ik(poses)
    assert one_line(e).startswith("poses[3]: pose (0, 0, 0) mm, (0, nan, 0) deg unreachable: not finite")
    with pytest.raises(ValueError) as e:
        pos.ik([0, 0, 12e-3, 0, 0, 0])  # one pose: no row index
    assert one_line(e).startswith("poses: pose (0, 0, 12) mm, (0, 0, 0) deg unreachable: out of reach: leg 0")


def test_fk_raises_for_legs_beyond_the_stroke_and_where_newton_finds_no_pose(pos):
    legs = np.zeros((3, 6))
    legs[2, 1] = 7e-3
    with pytest.raises(ValueError) as e:
        pos.fk(legs)
    assert one_line(e).startswith("legs[2]: forward kinematics: leg coordinates (0, 7, 0, 0, 0, 0) mm beyond")
    legs[2, 1] = np.inf
    with pytest.raises(ValueError) as e:
        pos.fk(legs)
    assert "legs[2]: forward kinematics: leg coordinates" in one_line(e) and "not finite" in str(e.value)
    # Leg coordinates anywhere in the stroke box are often no pose of the positioner: FK raises
    # ComputationFailed naming the row, never a wrong pose.
    rng = np.random.default_rng(99)
    failed = 0
    for q in rng.uniform(-HALF_STROKE, HALF_STROKE, (40, 6)):
        batch = np.zeros((2, 6))
        batch[1] = q
        try:
            pose = pos.fk(batch)[1]
        except ComputationFailed as e:
            assert isinstance(e, RuntimeError)
            assert str(e).startswith("legs[1]: forward kinematics of leg coordinates (") and "\n" not in str(e)
            failed += 1
            continue
        np.testing.assert_allclose(pos.ik(pose), q, rtol=0, atol=1e-12)
    assert failed > 0


@pytest.mark.parametrize("bad, message", [
    (np.zeros((3, 5)), "poses: expected shape (N, 6) or (6,) (got (3, 5))"),
    (np.zeros((2, 3, 6)), "poses: expected shape (N, 6) or (6,) (got (2, 3, 6))"),
    (np.zeros(5), "poses: expected shape (N, 6) or (6,) (got (5,))"),
    ([["a"] * 6], "poses: expected an array of numbers of shape (N, 6) or (6,)"),
])
def test_wrong_shapes_are_named_in_one_line(pos, bad, message):
    with pytest.raises(ValueError) as e:
        pos.ik(bad)
    assert one_line(e) == message


def test_bad_conventions_and_pivots_are_refused(pos):
    for kwargs, message in (
            (dict(convention="euler"), "convention: must be 'smarpod' or 'pi' (got 'euler')"),
            (dict(pivot_mode="moving"), "pivot_mode: must be 'relative' or 'fixed' (got 'moving')"),
            (dict(convention="pi", pivot_mode="fixed"),
             "pivot_mode 'fixed': PI's pivot always moves with the platform (use convention 'smarpod')"),
            (dict(pivot=[0, 0]), "pivot: expected 3 numbers (x, y, z) [m]")):
        with pytest.raises(ValueError) as e:
            pos.ik(np.zeros(6), **kwargs)
        assert one_line(e) == message


@pytest.mark.parametrize("make, what", [
    (lambda: np.zeros((4, 6), np.float32), "(got dtype float32)"),
    (lambda: np.zeros((4, 7)), "(got shape (4, 7))"),
    (lambda: np.zeros((6, 4)).T, "(got a non-C-contiguous array)"),
    (lambda: np.zeros((4, 12))[:, ::2], "(got a non-C-contiguous array)"),
])
def test_out_must_be_a_writeable_c_contiguous_float64_array_of_the_results_shape(pos, make, what):
    out = make()
    with pytest.raises(ValueError) as e:
        pos.ik(np.zeros((4, 6)), out=out)
    assert one_line(e) == "out: expected a writeable C-contiguous float64 array of shape (4, 6) " + what


def test_a_read_only_or_overlapping_out_is_refused(pos):
    ro = np.zeros((4, 6))
    ro.flags.writeable = False
    with pytest.raises(ValueError) as e:
        pos.ik(np.zeros((4, 6)), out=ro)
    assert one_line(e).endswith("(got a read-only array)")
    buf = np.zeros((5, 6))
    with pytest.raises(ValueError) as e:
        pos.ik(buf[:4], out=buf[1:])
    assert one_line(e) == "out: shares memory with poses (only the very same array may be both)"


# ---- out= ----------------------------------------------------------------------------------------

def test_out_is_written_in_place_and_returned(pos):
    poses = reachable_poses(pos, 50, 5)
    expected = pos.ik(poses)
    out = np.full((50, 6), np.nan)
    got = pos.ik(poses, out=out)
    assert got is out
    assert np.array_equal(out, expected)
    poses_back = np.full((50, 6), np.nan)
    assert pos.fk(out, out=poses_back) is poses_back
    np.testing.assert_allclose(poses_back, poses, rtol=0, atol=1e-11)
    # The very same array as input and output: each row is read before it is written.
    inplace = poses.copy()
    assert pos.ik(inplace, out=inplace) is inplace
    assert np.array_equal(inplace, expected)
    J = np.empty((50, 6, 6))
    assert pos.jacobian(poses, out=J) is J
    assert np.array_equal(J, pos.jacobian(poses))


def test_a_call_with_out_allocates_no_array(pos):
    poses = np.tile(reachable_poses(pos, 1, 5), (20000, 1))
    out = np.empty_like(poses)
    pos.ik(poses, out=out)  # warm up
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        pos.ik(poses, out=out)
        _, peak_out = tracemalloc.get_traced_memory()
        tracemalloc.reset_peak()
        pos.ik(poses)
        _, peak_new = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak_new >= poses.nbytes  # numpy's allocations are traced
    assert peak_out < 4096, peak_out


# ---- reachability, Jacobian, conditioning ----------------------------------------------------------

def test_check_gives_each_refused_poses_reason(pos):
    poses = np.zeros((5, 6))
    poses[1, 0] = 9e-3  # stroke
    poses[2, 2] = 12e-3  # above the vertical legs
    poses[3, 5] = np.nan
    c = pos.check(poses)
    assert c["reachable"].tolist() == [True, False, False, False, True]
    assert c["code"].tolist() == [0, 4, 2, 1, 0]
    assert c["reason"] == ["reachable", "stroke limit", "out of reach", "not finite", "reachable"]
    assert c["detail"][0] == "" and c["detail"][1].startswith("leg ") and "beyond its stroke +-6 mm" in c["detail"][1]
    assert c["conditioning"][0] == pytest.approx(0.41, abs=0.01)
    assert c["conditioning"][2] == 0.0 and c["conditioning"][3] == 0.0
    assert pos.reachable(poses).tolist() == c["reachable"].tolist()
    one = pos.check(poses[1])
    assert one["reachable"] is False and one["reason"] == "stroke limit" and one["detail"] == c["detail"][1]
    assert pos.reachable(np.zeros(6)) is True


def test_the_jacobian_is_the_ik_s_derivative_and_gives_the_conditioning(pos):
    poses = reachable_poses(pos, 5, 17)
    J = pos.jacobian(poses)
    assert J.shape == (5, 6, 6)
    T = positioner.to_transform(poses)
    rng = np.random.default_rng(1)
    h = 1e-7
    for i in range(len(poses)):
        twist = rng.normal(size=6)
        moved = []
        for s in (+h, -h):
            Ts = T[i].copy()
            Ts[:3, :3] = Rotation.from_rotvec(s * twist[3:]).as_matrix() @ T[i][:3, :3]
            Ts[:3, 3] += s * twist[:3]
            moved.append(pos.ik(positioner.from_transform(Ts)))
        np.testing.assert_allclose((moved[0] - moved[1]) / (2 * h), J[i] @ twist, rtol=0, atol=1e-7)
        scaled = J[i].copy()
        scaled[:, 3:] /= P_RADIUS
        sv = np.linalg.svd(scaled, compute_uv=False)
        assert pos.conditioning(poses[i]) == pytest.approx(sv[-1] / sv[0], rel=1e-12)
    np.testing.assert_array_equal(pos.conditioning(poses), pos.check(poses)["conditioning"])
    with pytest.raises(ValueError) as e:
        pos.jacobian([0, 0, 12e-3, 0, 0, 0])
    assert one_line(e).startswith("poses: pose (0, 0, 12) mm, (0, 0, 0) deg has no Jacobian: out of reach")
    with pytest.raises(ValueError) as e:
        pos.conditioning([[0, 0, 0, 0, 0, 0], [0, np.nan, 0, 0, 0, 0]])
    assert one_line(e) == "poses[1]: non-finite value nan"


# ---- conventions and pivot -------------------------------------------------------------------------

def test_poses_convert_between_smarpod_and_pi_through_the_transform(pos):
    poses = reachable_poses(pos, 10, 23)
    T = positioner.to_transform(poses)
    np.testing.assert_allclose(T[:, :3, :3], Rotation.from_euler("xyz", poses[:, 3:]).as_matrix(), atol=1e-15)
    np.testing.assert_array_equal(T[:, :3, 3], poses[:, :3])
    pi = positioner.from_transform(T, convention="pi")
    np.testing.assert_allclose(pi[:, 3:], Rotation.from_matrix(T[:, :3, :3]).as_euler("XYZ"), atol=1e-14)
    np.testing.assert_allclose(pos.ik(pi, convention="pi"), pos.ik(poses), rtol=0, atol=1e-15)
    np.testing.assert_allclose(positioner.from_transform(T), poses, rtol=0, atol=1e-15)
    with pytest.raises(ValueError) as e:
        positioner.from_transform(np.diag([1.0, 2.0, 1.0, 1.0]))
    assert one_line(e).startswith("transforms: not a rigid transform [R d; 0 0 0 1]")


def test_the_pivot_modes_are_the_librarys_equations():
    pose = np.array([1e-3, 2e-3, -1e-3, 0.05, -0.04, 0.03])
    c = np.array([0.0, 1e-3, 10e-3])
    R = Rotation.from_euler("xyz", pose[3:]).as_matrix()
    rel = positioner.to_transform(pose, pivot=c)
    fixed = positioner.to_transform(pose, pivot=c, pivot_mode="fixed")
    np.testing.assert_allclose(rel[:3, 3], pose[:3] + c - R @ c, rtol=0, atol=1e-16)  # d = t + (I - R) c
    np.testing.assert_allclose(fixed[:3, 3], R @ pose[:3] + c - R @ c, rtol=0, atol=1e-16)  # d = R t + (I - R) c
    np.testing.assert_allclose(positioner.from_transform(fixed, pivot=c, pivot_mode="fixed"), pose, rtol=0,
                               atol=1e-15)


# ---- workspace -------------------------------------------------------------------------------------

def test_rotation_ranges_are_the_command_lines(pos, cli):
    code, out, err = cli("positioner", "workspace", "--json", "--points", "2")
    assert code == 0, err
    ranges = json.loads(out)["rotation_range"]
    for axis in ("rx", "ry", "rz"):
        r = pos.rotation_range(np.zeros(6), axis)
        assert (r["min_rad"], r["max_rad"]) == (ranges[axis]["min"], ranges[axis]["max"])
        assert (r["min_reason"], r["max_reason"]) == (ranges[axis]["min_reason"], ranges[axis]["max_reason"])
    # ry about the plate's centre and about a point 10 mm above it (the concept page's figures).
    at = np.zeros((2, 6))
    at[1, 0] = 1e-3
    r = pos.rotation_range(at, "ry")
    assert r["max_rad"].shape == (2,) and len(r["max_reason"]) == 2
    assert np.degrees(r["max_rad"][0]) == pytest.approx(12.1, abs=0.05)
    assert np.degrees(pos.rotation_range(np.zeros(6), "ry", pivot=[0, 0, 10e-3])["max_rad"]) == pytest.approx(9.0, abs=0.05)
    with pytest.raises(ValueError) as e:
        pos.rotation_range(np.array([[0, 0, 0, 0, 0, 0], [9e-3, 0, 0, 0, 0, 0]]), "rz")
    assert one_line(e).startswith("at[1]: pose (9, 0, 0) mm, (0, 0, 0) deg unreachable: stroke limit")
    with pytest.raises(ValueError) as e:
        pos.rotation_range(np.zeros(6), "x")
    assert one_line(e) == "axis: must be 'rx', 'ry' or 'rz' (got 'x')"


def test_a_workspace_slice_is_the_check_of_its_grid(pos):
    s = pos.workspace_slice(a="z", b="rz", range_a=(-10e-3, 10e-3), range_b=(-0.2, 0.2), points=(31, 21))
    assert s["a"] == "z" and s["b"] == "rz" and s["reach"].shape == (21, 31)
    grid = np.stack([s[k] for k in ("x_m", "y_m", "z_m", "rx_rad", "ry_rad", "rz_rad")], axis=-1)
    np.testing.assert_allclose(grid[0, :, 2], np.linspace(-10e-3, 10e-3, 31), rtol=0, atol=1e-17)
    np.testing.assert_allclose(grid[:, 0, 5], np.linspace(-0.2, 0.2, 21), rtol=0, atol=1e-16)
    c = pos.check(grid.reshape(-1, 6))
    np.testing.assert_array_equal(s["reach"].ravel(), c["code"])
    np.testing.assert_array_equal(s["conditioning"].ravel(), c["conditioning"])
    assert {s["reasons"][k] for k in np.unique(s["reach"])} >= {"reachable", "out of reach", "stroke limit"}
    with pytest.raises(ValueError) as e:
        pos.workspace_slice(a="z", b="z")
    assert one_line(e) == "b: must be another coordinate than a ('z')"
    with pytest.raises(ValueError) as e:
        pos.workspace_slice(range_a=(1, 0))
    assert one_line(e) == "range_a: expected (lo, hi), finite, lo < hi, in m or rad"
