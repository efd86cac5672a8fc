"""airtwin.manipulation_region against `airtwin region` (the same files, byte for byte), against
eq. (8) predicted by airtwin.predict for the same pushes, and its counts against the arrays."""

import json
import os
import subprocess
import tempfile

import numpy as np
import pytest

import airtwin
from conftest import SOURCE_DIR

SMALL = dict(extent_m=0.4, step_m=0.4, directions=4)
CONSTRUCTED = os.path.join(SOURCE_DIR, "models/data/constructed_field_table.csv")
PAPER = dict(air="model", drag="eq8", table=CONSTRUCTED)


def test_the_module_writes_what_the_cli_writes():
    r = airtwin.manipulation_region(twin=True, seed=3, **SMALL, **PAPER)
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([os.environ["AIRTWIN_BINARY"], "region", "--extent", "0.4", "--step", "0.4",
                        "--directions", "4", "--twin", "--seed", "3", "--air", "model", "--drag",
                        "eq8", "--table", CONSTRUCTED, "--quiet", "--trajectories-out",
                        os.path.join(d, "tr.csv"), "--out", d],
                       check=True, capture_output=True)
        with open(os.path.join(d, "region.csv")) as f:
            assert r.csv() == f.read()
        with open(os.path.join(d, "region.json")) as f:
            assert r.summary_json() == f.read()
        with open(os.path.join(d, "tr.csv")) as f:
            assert r.trajectories_csv() == f.read()


def test_model_ends_are_eq8_predicted_for_each_push():
    # The paper's eq. (8) in the constructed field: each push's end as airtwin.predict gives it.
    field = airtwin.Field.constructed()
    r = airtwin.manipulation_region(**SMALL, **PAPER)
    tracer = np.array(airtwin.object_dynamics("tracer"))
    for i, p in enumerate(r.points):
        pan_deg, tilt_deg = airtwin.aim(*r.stagnation_points[i], field=field)
        end = airtwin.predict(field, pan_deg, tilt_deg, p[None, :], tracer[None, :],
                              horizon_s=1.5).end[0, :2]
        assert np.allclose(r.model_end[i], end, rtol=0, atol=1e-9), i
        assert r.model_along_m[i] == pytest.approx(np.dot(end - p, r.directions[i]), abs=1e-9)
    assert np.isnan(r.twin_end).all() and np.isnan(r.twin_along_m).all()
    with pytest.raises(ValueError, match="without twin=True"):
        r.trajectories_csv()


def test_counts_are_the_arrays_counted():
    r = airtwin.manipulation_region(twin=True, **SMALL, **PAPER)
    j = json.loads(r.summary_json())
    model = r.model_along_m >= 0.01
    twin = r.twin_along_m >= 0.01
    classes = np.array(r.classes)
    assert j["model"]["moved"] == model.sum() and j["twin"]["moved"] == twin.sum()
    for c in ("away", "across", "toward"):
        assert j["model"]["by_class"][c]["moved"] == model[classes == c].sum()
        assert j["twin"]["by_class"][c]["of"] == (classes == c).sum()
    assert j["agreement"]["both"] == (model & twin).sum()
    assert j["agreement"]["twin_only"] == (~model & twin).sum()
    # Rows of a point are its directions counter-clockwise from +x.
    assert np.allclose(r.directions[:4], [[1, 0], [0, 1], [-1, 0], [0, -1]], atol=1e-15)
    assert np.allclose(r.stagnation_points, r.points - 0.418 * r.directions, atol=1e-15)


def test_bad_values_raise_value_error_naming_the_field():
    with pytest.raises(ValueError, match="region.step_m"):
        airtwin.manipulation_region(step_m=0.0)
    with pytest.raises(ValueError, match="region.object"):
        airtwin.manipulation_region(object="brick")
    with pytest.raises(ValueError, match="air"):
        airtwin.manipulation_region(twin=True, air="wind", **SMALL)
    with pytest.raises(ValueError, match="effects: needs twin=True"):
        airtwin.manipulation_region(effects=["stiction"], **SMALL)
