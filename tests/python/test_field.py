"""airtwin.Field and airtwin.CfdField against the C++ figures on the same points."""

import csv
import os
import subprocess

import numpy as np
import pytest

import airtwin
from conftest import SOURCE_DIR, expect_cli_error, run_cli

ORIENTATIONS = [(0.0, 0.0), (30.0, 22.5), (-135.0, 45.0), (200.0, 60.0)]


def random_points(n, seed=7):
    return np.random.default_rng(seed).uniform(-1.5, 1.5, size=(n, 2))


def reference_velocity(table, pan_deg, tilt_deg, points):
    """The field evaluated by the C++ library in tests/python/field_reference, exact floats."""
    text = "".join(f"{x.hex()} {y.hex()}\n" for x, y in points.tolist())
    done = subprocess.run([os.environ["AIRTWIN_FIELD_REFERENCE"], table, repr(pan_deg),
                           repr(tilt_deg)], input=text, capture_output=True, text=True,
                          check=True)
    return np.array([[float.fromhex(v) for v in line.split()]
                     for line in done.stdout.splitlines()])


def cli_grid(tmp_path, *args):
    """`airtwin field` on the 0.4 m grid of 0.1 m steps: points (N x 2), velocities (N x 2)."""
    out = tmp_path / "field.csv"
    status, _, stderr = run_cli("field", *args, "--extent", 0.4, "--step", 0.1, "--out", out)
    assert status == 0, stderr
    with open(out, newline="") as f:
        rows = [[float(r[k]) for k in ("x", "y", "vx", "vy")] for r in csv.DictReader(f)]
    grid = np.array(rows)
    return grid[:, :2], grid[:, 2:]


@pytest.mark.parametrize("pan_deg,tilt_deg", ORIENTATIONS)
def test_default_field_equals_the_cpp_library_bit_for_bit(pan_deg, tilt_deg):
    points = random_points(500)
    v = airtwin.Field.default().velocity(pan_deg, tilt_deg, points)
    assert v.shape == (500, 2) and v.dtype == np.float64
    assert np.array_equal(v, reference_velocity("default", pan_deg, tilt_deg, points))


def test_field_model_file_equals_the_cpp_library_bit_for_bit():
    path = os.path.join(SOURCE_DIR, "models/data/cfd_fitted_field_model.json")
    points = random_points(300, seed=3)
    v = airtwin.Field.from_file(path).velocity(40.0, 30.0, points)
    assert np.array_equal(v, reference_velocity(path, 40.0, 30.0, points))
    # Another model than the constructed table's: the file was read.
    assert not np.array_equal(v, airtwin.Field.constructed().velocity(40.0, 30.0, points))


def test_shipped_files_equal_the_compiled_in_models():
    points = random_points(200, seed=5)
    table = airtwin.Field.from_file(os.path.join(SOURCE_DIR, "models/data/constructed_field_table.csv"))
    assert np.array_equal(table.velocity(10.0, 35.0, points),
                          airtwin.Field.constructed().velocity(10.0, 35.0, points))
    fitted = airtwin.Field.from_file(os.path.join(SOURCE_DIR, "models/data/cfd_fitted_field_model.json"))
    assert np.array_equal(fitted.velocity(10.0, 35.0, points),
                          airtwin.Field.default().velocity(10.0, 35.0, points))
    assert not np.array_equal(fitted.velocity(10.0, 35.0, points),
                              table.velocity(10.0, 35.0, points))


@pytest.mark.parametrize("pan_deg,tilt_deg", ORIENTATIONS[1:3])
def test_model_field_equals_the_cli_grid_to_its_printed_digits(tmp_path, pan_deg, tilt_deg):
    points, v_cli = cli_grid(tmp_path, "--pan", pan_deg, "--tilt", tilt_deg)
    v = airtwin.Field.default().velocity(pan_deg, tilt_deg, points)
    assert np.max(np.abs(v - v_cli)) <= 5e-7 + 1e-12  # %.6f rounds to half a unit


def test_cfd_field_equals_the_cli_grid_to_its_printed_digits(tmp_path):
    points, v_cli = cli_grid(tmp_path, "--pan", 30, "--tilt", 37.5, "--source", "cfd")
    cfd = airtwin.CfdField.read_dir()
    v = cfd.velocity(30.0, 37.5, points)
    assert np.max(np.abs(v - v_cli)) <= 5e-7 + 1e-12
    assert np.max(np.hypot(v[:, 0], v[:, 1])) > 0.5  # the jet is there
    assert cfd.min_tilt_deg <= 37.5 <= cfd.max_tilt_deg


def test_arrays_of_other_layouts_and_dtypes_give_the_same_figures():
    field = airtwin.Field.default()
    points = random_points(100)
    v = field.velocity(15.0, 25.0, points)
    fortran = np.asfortranarray(points)
    strided = np.repeat(points, 2, axis=0)[::2]
    assert np.array_equal(field.velocity(15.0, 25.0, fortran), v)
    assert np.array_equal(field.velocity(15.0, 25.0, strided), v)
    assert np.array_equal(field.velocity(15.0, 25.0, points.tolist()), v)
    whole = np.array([[1, 0], [0, -1]])
    assert np.array_equal(field.velocity(15.0, 25.0, whole),
                          field.velocity(15.0, 25.0, whole.astype(float)))
    assert field.velocity(15.0, 25.0, np.zeros((0, 2))).shape == (0, 2)
    # Into the caller's array, in place.
    out = np.full((100, 2), np.nan)
    assert field.velocity(15.0, 25.0, points, out=out) is out
    assert np.array_equal(out, v)
    for bad in (np.zeros((100, 2), dtype=np.float32), np.zeros((99, 2)), np.zeros((2, 100)).T):
        with pytest.raises(ValueError, match=r"^out: expected a writeable C-contiguous float64"):
            field.velocity(15.0, 25.0, points, out=bad)


def test_bad_input_raises_value_error_with_the_cli_message(tmp_path):
    bad = tmp_path / "bad_table.csv"
    bad.write_text("tilt_deg,alpha_deg,b1,b2,b3\n0,0,1,-1,x\n")
    message = expect_cli_error(lambda: airtwin.Field.from_file(str(bad)), "field", "--pan", 0,
                               "--tilt", 10, "--table", bad, "--out", tmp_path / "f.csv")
    assert "bad_table.csv:2" in message
    missing = tmp_path / "missing.csv"
    expect_cli_error(lambda: airtwin.Field.from_file(str(missing)), "field", "--pan", 0, "--tilt",
                     10, "--table", missing, "--out", tmp_path / "f.csv")


def test_bad_orientation_and_shape_raise_value_error():
    field = airtwin.Field.default()
    # Beyond eq. (2)'s fold with the default model's a1, a2 (88.7 deg).
    with pytest.raises(ValueError, match=r"^nozzle orientation: tilt 89\.000000 deg .*fold"):
        field.velocity(0.0, 89.0, random_points(3))
    with pytest.raises(ValueError, match=r"^points: expected an N x 2 array, got shape \(3,\)$"):
        field.velocity(0.0, 10.0, np.zeros(3))
    with pytest.raises(ValueError, match=r"got shape \(4, 3\)$"):
        field.velocity(0.0, 10.0, np.zeros((4, 3)))
    with pytest.raises(ValueError):
        airtwin.CfdField.read_dir().velocity(0.0, 63.0, random_points(3))


def test_probe_air_equals_the_cli_probe_to_its_printed_digits(tmp_path):
    """probe_air and `airtwin probe` on the same re-aim: the same air at every record."""
    program = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.156, 0.0, 22.5]])
    points = np.array([[0.3, 0.0005, 0.004], [0.7, 0.2, 0.015], [-0.2, 0.1, 0.004]])
    cfd = airtwin.CfdField.read_dir()
    t, u = airtwin.probe_air(program, points, cfd=cfd, end_s=0.8, interval_s=0.02)
    assert t.shape == (41,) and u.shape == (41, 3, 2)
    with open(tmp_path / "program.csv", "w") as f:
        f.write("t_s,pan_deg,tilt_deg\n" + "".join("%r,%r,%r\n" % tuple(r) for r in program))
    with open(tmp_path / "points.csv", "w") as f:
        f.write("x_m,y_m,z_m\n" + "".join("%r,%r,%r\n" % tuple(r) for r in points))
    status, _, stderr = run_cli("probe", "--program", tmp_path / "program.csv", "--points",
                                tmp_path / "points.csv", "--end", 0.8,
                                "--interval", 0.02, "--out", tmp_path / "u.csv")
    assert status == 0, stderr
    with open(tmp_path / "u.csv", newline="") as f:
        rows = np.array([[float(r[k]) for k in ("ux", "uy")] for r in csv.DictReader(f)])
    np.testing.assert_allclose(u.reshape(-1, 2), rows, atol=6e-6)
    # the air changes: the old jet's at the start, the new one's at the end
    assert np.linalg.norm(u[-1] - u[0], axis=1).max() > 1.0
    # it forms over time by default: without the formation the new air comes at once
    _, whole = airtwin.probe_air(program, points, cfd=cfd, formation=False, end_s=0.8,
                                 interval_s=0.02)
    assert np.abs(whole - u).max() > 0.5
    with pytest.raises(ValueError, match="formation_time_scale"):
        airtwin.probe_air(program, points, formation=False, formation_time_scale=0.25)
    # the front of still air, as the CLI's --air-front-co-flow 0
    _, still = airtwin.probe_air(program, points, cfd=cfd, end_s=0.8, interval_s=0.02,
                                 front_co_flow=0.0)
    status, _, stderr = run_cli("probe", "--program", tmp_path / "program.csv", "--points",
                                tmp_path / "points.csv", "--end", 0.8, "--interval", 0.02,
                                "--air-front-co-flow", 0, "--out", tmp_path / "still.csv")
    assert status == 0, stderr
    with open(tmp_path / "still.csv", newline="") as f:
        rows = np.array([[float(r[k]) for k in ("ux", "uy")] for r in csv.DictReader(f)])
    np.testing.assert_allclose(still.reshape(-1, 2), rows, atol=6e-6)
    assert np.abs(still - u).max() > 0.1  # the carried front came sooner somewhere
    with pytest.raises(ValueError, match="front_co_flow: expected \\[0, 2\\]"):
        airtwin.probe_air(program, points, front_co_flow=-1.0)
    with pytest.raises(ValueError, match="air_probe.interval_s"):
        airtwin.probe_air(program, points, interval_s=0.003)
    with pytest.raises(ValueError, match="points"):
        airtwin.probe_air(program, points[:, :2])


def test_the_formation_asked_for_on_cases_without_pulses_raises(tmp_path):
    """Cases without the start-up and pulses give the lag's air alone, unless the formation is
    asked for: then ValueError naming the keyword, in probe_air and in the twin's set-up."""
    cases = tmp_path / "cases"
    cases.mkdir()
    for name in ("tilt00.0_mesh1_d20", "tilt22.5_mesh1_d20"):
        for ext in (".json", ".f32"):
            (cases / (name + ext)).symlink_to(os.path.join(SOURCE_DIR, "data/cfd", name + ext))
    bare = airtwin.CfdField.read_dir(str(cases))
    program = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 20.0]])
    points = np.array([[0.8, 0.0, 0.015]])
    _, formed = airtwin.probe_air(program, points, cfd=bare, end_s=0.5)
    _, lag_only = airtwin.probe_air(program, points, cfd=bare, formation=False, end_s=0.5)
    np.testing.assert_array_equal(formed, lag_only)
    with pytest.raises(ValueError, match="formation: the CFD cases lack the jet's start-up"):
        airtwin.probe_air(program, points, cfd=bare, formation=True)
    with pytest.raises(ValueError, match="air_formation: the CFD cases lack the jet's start-up"):
        airtwin.Twin(os.path.join(SOURCE_DIR, "scenes/line.yaml"), 1, cfd=bare, air_formation=True)
