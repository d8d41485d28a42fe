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
