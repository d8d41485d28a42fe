"""microcobot.vision against the CLI and an independent PNG reader (PIL): the frame `vision render`
writes reads back with the right size, bit depth and pixels; render() returns the same frame as a
numpy array; camera_model() the same figures as `vision model --json`; bad input fails cleanly."""

import json
import os

import numpy as np
import pytest

import microcobot
from conftest import cli_error

Image = pytest.importorskip("PIL.Image")


@pytest.mark.parametrize("bits,dtype,mode", [(8, np.uint8, "L"), (12, np.uint16, "I;16")])
def test_cli_png_reads_back_and_equals_the_python_frame(cli, tmp_path, bits, dtype, mode):
    out = tmp_path / f"frame{bits}"
    code, _, err = cli("vision", "render", "--scene", "pin-in-hole", "--objective", "10x", "--focus-um", "600",
                       "--bit-depth", bits, "--seed", 5, "--frame", 2, "--out", out)
    assert code == 0, err
    with Image.open(out / "frame.png") as im:
        assert im.size == (1280, 1024)
        assert im.mode.startswith(mode[:1]) and (bits == 8) == (im.mode == "L")
        pixels = np.array(im)
    state = json.loads((out / "camera.json").read_text())
    assert state["bit_depth"] == bits and state["objective"] == "10x" and state["seed"] == 5
    assert state["focus_z_m"] == pytest.approx(600e-6)
    frame = microcobot.vision.render("pin-in-hole", "10x", focus_um=600, bit_depth=bits, seed=5, frame=2)
    assert frame.dtype == dtype and frame.shape == (1024, 1280)
    assert pixels.max() <= (1 << bits) - 1
    np.testing.assert_array_equal(pixels.astype(np.int64), frame.astype(np.int64))
    assert sorted(os.listdir(out)) == ["camera.json", "frame.png"]


@pytest.mark.parametrize("bits,mode", [(8, "L"), (12, "I;16")])
def test_cli_tiff_reads_back_with_its_scale_and_state(cli, tmp_path, bits, mode):
    # The same frame as the PNG, as a baseline TIFF read by Pillow's own decoder: the pixels, the
    # object-side scale in the resolution tags (pixels per cm) and the camera state as JSON.
    out = tmp_path / f"tiff{bits}"
    code, _, err = cli("vision", "render", "--scene", "pin-in-hole", "--objective", "10x", "--focus-um", "600",
                       "--bit-depth", bits, "--seed", 5, "--frame", 2, "--format", "tiff", "--out", out)
    assert code == 0, err
    assert sorted(os.listdir(out)) == ["camera.json", "frame.tiff"]
    state = json.loads((out / "camera.json").read_text())
    assert state["image"] == "frame.tiff"
    with Image.open(out / "frame.tiff") as im:
        assert im.format == "TIFF" and im.size == (1280, 1024) and im.mode == mode
        pixels = np.array(im)
        tags = im.tag_v2
        assert tags[296] == 3  # ResolutionUnit: centimetre
        assert float(tags[282]) == pytest.approx(1e4 / state["um_per_px"], rel=1e-6)
        assert float(tags[283]) == pytest.approx(1e4 / state["um_per_px"], rel=1e-6)
        assert tuple(np.atleast_1d(tags[281])) == ((1 << bits) - 1,)  # MaxSampleValue, one per sample
        assert json.loads(tags[270]) == state
    frame = microcobot.vision.render("pin-in-hole", "10x", focus_um=600, bit_depth=bits, seed=5, frame=2)
    np.testing.assert_array_equal(pixels.astype(np.int64), frame.astype(np.int64))
    code, _, err = cli("vision", "render", "--format", "bmp", "--out", tmp_path / "bmp")
    assert code == 2 and "bmp" in err and not (tmp_path / "bmp").exists()


def test_camera_model_matches_the_cli(cli):
    code, out, err = cli("vision", "model", "--objective", "50x", "--json")
    assert code == 0, err
    ref = json.loads(out)
    got = microcobot.vision.camera_model("50x")
    for key in ("resolution_m", "dof_m", "um_per_px", "field_of_view_x_m", "psf_fwhm_m"):
        assert got[key] == pytest.approx(ref[key], rel=1e-12), key
    assert got["resolution_m"] == pytest.approx(0.61 * 550e-9 / 0.55)


def test_bad_input_names_what_was_given(cli, tmp_path):
    with pytest.raises(ValueError, match="objective '7x'"):
        microcobot.vision.render(objective="7x")
    with pytest.raises(ValueError, match="bit_depth"):
        microcobot.vision.render(bit_depth=20)
    code, _, err = cli("vision", "render", "--objective", "7x", "--out", tmp_path / "bad")
    assert code == 2 and "7x" in cli_error(err)
    assert not (tmp_path / "bad").exists()
    code, _, err = cli("vision", "render", "--exposure-ms", "-1", "--out", tmp_path / "bad")
    assert code == 2 and "--exposure-ms" in cli_error(err)
    code, _, err = cli("vision", "render", "--scene", "nowhere.yaml", "--out", tmp_path / "bad")
    assert code == 3 and "nowhere.yaml" in cli_error(err)
    assert not (tmp_path / "bad").exists()


# ---- what the frames measure --------------------------------------------------------

def _tool_frame(x_um, y_um, seed_frame):
    # 10x, the focus on the gripper's tips (450 um above the substrate), the tool at (x, y).
    return microcobot.vision.render("pick-place", "10x", focus_um=450, tool_um=(x_um, y_um, 450),
                                    seed=3, frame=seed_frame)


def test_tracker_follows_the_tool_by_its_commanded_move():
    um_per_px = microcobot.vision.camera_model("10x")["um_per_px"]
    first = _tool_frame(-200, 0, 0)
    t = microcobot.vision.TemplateTracker()
    # The open gripper's right finger is in this view (the part's centre): its tip's end at about
    # column 832, row 549.
    start = t.set_template(first, (784, 482, 96, 96))
    assert start["found"] and start["u_px"] == pytest.approx(831.5)
    moved = _tool_frame(-194.0, 3.0, 1)  # 6 um right, 3 um up (rows go down)
    e = t.track(moved)
    assert e.found and e.confidence > 0.9
    assert e.u_px - start["u_px"] == pytest.approx(6.0 / um_per_px, abs=0.1)
    assert e.v_px - start["v_px"] == pytest.approx(-3.0 / um_per_px, abs=0.1)
    near = t.track_near(moved, e.u_px + 5, e.v_px - 5)
    assert near.u_px == pytest.approx(e.u_px, abs=0.02)


def test_autofocus_steps_from_python_to_the_tips_height():
    af = microcobot.vision.Autofocus("10x", start_um=380.0, range_um=(-500, 2000))
    roi = (784, 537, 96, 24)  # a strip across the right finger's tip end
    while not af.done:
        frame = microcobot.vision.render("pick-place", "10x", focus_um=af.next_focus_um, seed=4,
                                         frame=af.frames_used)
        af.observe(microcobot.vision.sharpness(frame, roi, af.next_metric))
    assert af.converged, af.status
    assert af.frames_used <= 15
    dof_um = microcobot.vision.camera_model("10x")["dof_m"] * 1e6
    assert abs(af.best_focus_um - 450.0) < dof_um / 5


def test_autofocus_scans_a_wide_region_and_refines_on_the_tips_strip():
    """The coarse scan measured on a square around the tips (next_is_coarse), the refinement on
    the strip: the search must not take a sample of one region as the other's."""
    strip, box = (784, 537, 96, 24), (736, 453, 192, 192)
    dof_um = microcobot.vision.camera_model("10x")["dof_m"] * 1e6
    for start in (350.0, 550.0):
        af = microcobot.vision.Autofocus("10x", start_um=start, range_um=(-500, 2000),
                                         reuse_coarse_samples=False)
        assert af.next_is_coarse
        coarse = 0
        while not af.done:
            frame = microcobot.vision.render("pick-place", "10x", focus_um=af.next_focus_um, seed=4,
                                             frame=af.frames_used)
            coarse += af.next_is_coarse
            af.observe(microcobot.vision.sharpness(frame, box if af.next_is_coarse else strip,
                                                   af.next_metric))
        assert af.converged, af.status
        assert 2 < coarse < af.frames_used <= 15
        assert abs(af.best_focus_um - 450.0) < dof_um / 5


def test_fit_affine_recovers_a_known_map():
    rng = np.random.default_rng(8)
    a = np.array([[1.9e6, -0.08e6], [-0.07e6, -1.88e6]])
    stage = rng.uniform(-1e-4, 1e-4, size=(20, 2))
    pixel = stage @ a.T + np.array([640.0, 512.0]) + rng.normal(0, 0.02, size=(20, 2))
    fit = microcobot.vision.fit_affine(stage, pixel)
    np.testing.assert_allclose(fit["A_px_per_m"], a, rtol=2e-3)
    assert fit["residual_rms_px"] < 0.04 and fit["residuals_px"].shape == (20, 2)


def test_vision_measures_refuse_bad_input():
    frame = _tool_frame(-200, 0, 0)
    with pytest.raises(ValueError, match="2-D uint8 or uint16"):
        microcobot.vision.sharpness(frame.astype(np.float32))
    with pytest.raises(ValueError, match="sharpest"):
        microcobot.vision.sharpness(frame, None, "sharpest")
    t = microcobot.vision.TemplateTracker()
    with pytest.raises(ValueError, match="not inside"):
        t.set_template(frame, (1250, 10, 64, 64))
    with pytest.raises(ValueError, match="ecc_blur_px"):
        microcobot.vision.TemplateTracker(ecc_blur_px=4)
    with pytest.raises(ValueError, match="ecc_highpass_px"):
        microcobot.vision.TemplateTracker(ecc_highpass_px=float("nan"))
    with pytest.raises(ValueError, match="line"):
        microcobot.vision.fit_affine(np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="start_um"):
        microcobot.vision.Autofocus("10x", start_um=float("nan"))


def _servo_run(believed_scale, start_um, seed):
    """A stage point seen through the true map, servoed through the believed one: 30 fps frames,
    10 ms from mid-exposure to the command, each command held 13 ms (a stick-slip stage moves
    between exposures). Returns the true distance to the target after each frame [m]."""
    rng = np.random.default_rng(seed)
    a_true = np.array([[1.88e6, 0.03e6], [0.02e6, -1.89e6]])  # px/m, y mirrored (rows go down)
    b = np.array([640.0, 512.0])
    servo = microcobot.vision.VisualServo(a_true * believed_scale, tuple(b), 1280, 1024)
    target_m = np.zeros(2)
    servo.set_target(*(a_true @ target_m + b))
    angle = rng.uniform(0, 2 * np.pi)
    stage = start_um * 1e-6 * np.array([np.cos(angle), np.sin(angle)])
    period, latency, hold = 1 / 30, 10e-3, 13e-3
    errors = []
    for k in range(40):
        t_mid = k * period
        pixel = a_true @ stage + b + rng.normal(0, 0.02, 2)  # the tracker's noise
        cmd = servo.step(pixel[0], pixel[1], True, t_mid, t_mid + latency, hold)
        stage = stage + np.array(cmd["velocity_m_s"]) * hold  # done before the next exposure
        errors.append(np.linalg.norm(stage - target_m))
    return errors, cmd


@pytest.mark.parametrize("scale", [1.0, 1.05, 0.95])
def test_visual_servo_steps_from_python_to_the_target(scale):
    for seed in (21, 22):  # directions no parameter was chosen on
        errors, last = _servo_run(scale, 50.0, seed)
        converged = next(k for k in range(len(errors)) if max(errors[k:]) <= 0.3e-6)
        assert converged < 30, (scale, seed, errors[:10])
        assert errors[-1] <= 0.3e-6
        assert last["status"] == "converged"


def test_visual_servo_holds_when_the_feature_is_lost_and_refuses_bad_input():
    a = np.array([[1.9e6, 0.0], [0.0, -1.9e6]])
    servo = microcobot.vision.VisualServo(a, (640.0, 512.0), 1280, 1024)
    servo.set_target(700.0, 500.0)
    cmd = servo.step(600.0, 520.0, False, 0.0, 0.01)
    assert cmd["velocity_m_s"] == (0.0, 0.0) and cmd["status"] == "hold (target lost)"
    moving = servo.step(600.0, 520.0, True, 0.1, 0.11)
    assert moving["status"] == "moving" and moving["velocity_m_s"][0] > 0
    with pytest.raises(ValueError, match="gain_per_s"):
        microcobot.vision.VisualServo(a, (640.0, 512.0), 1280, 1024, gain_per_s=float("nan"))
    with pytest.raises(ValueError, match="2 x 2"):
        microcobot.vision.VisualServo(np.zeros(3), (640.0, 512.0), 1280, 1024)
    with pytest.raises(ValueError):
        microcobot.vision.VisualServo(np.zeros((2, 2)), (640.0, 512.0), 1280, 1024)
    with pytest.raises(ValueError, match="inside"):
        servo.set_target(1300.0, 10.0)
    with pytest.raises(ValueError, match="finite"):
        servo.step(600.0, 520.0, True, float("nan"), 0.0)


def test_the_rotary_axis_turns_the_fingers_about_the_tool_point_and_the_part_with_them():
    """The camera sees the fingers turned about the tool point (the rotary axis
    under the gripper) and the part at its yaw; turning moves grey level around, it does not add or
    remove any (the same objects, the same areas), and the turned fingers' tips end where the turn
    puts them."""
    kw = dict(scene="pin-in-hole", objective="5x", focus_um=300.0, bit_depth=8, tool_um=(0.0, 0.0, 320.0))
    flat = microcobot.vision.render(**kw).astype(np.float64)
    turned = microcobot.vision.render(**kw, tool_yaw_deg=30.0, part_yaw_deg=30.0).astype(np.float64)
    assert abs(turned.mean() - flat.mean()) < 0.005 * flat.mean()
    assert np.abs(turned - flat).mean() > 0.5  # something moved
    with pytest.raises(ValueError, match="tool_yaw_deg"):
        microcobot.vision.render(**kw, tool_yaw_deg=float("nan"))
