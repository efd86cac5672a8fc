"""airtwin.aim and airtwin.stagnation_point against `airtwin aim` and eqs. (1)-(2)."""

import json

import numpy as np
import pytest

import airtwin
from conftest import cli_error, run_cli

TARGETS = [(0.3, 0.1), (-0.5, 0.42), (0.0, -1.2), (1.1, 1.1)]


@pytest.mark.parametrize("x,y", TARGETS)
def test_aim_equals_the_cli_bit_for_bit(x, y):
    status, stdout, stderr = run_cli("aim", "--stagnation", f"{x!r},{y!r}")
    assert status == 0, stderr
    cli = json.loads(stdout)
    pan_deg, tilt_deg = airtwin.aim(x, y)
    assert (pan_deg, tilt_deg) == (cli["pan_deg"], cli["tilt_deg"])
    # The CLI evaluates eq. (2) at the angles in radians; here they went through degrees and
    # back, which may cost the last bit.
    assert np.allclose(airtwin.stagnation_point(pan_deg, tilt_deg), cli["stagnation"], rtol=0,
                       atol=1e-15)


@pytest.mark.parametrize("x,y", TARGETS)
def test_aim_puts_the_stagnation_point_back_on_the_target(x, y):
    pan_deg, tilt_deg = airtwin.aim(x, y)
    assert 0.0 <= tilt_deg <= 60.0
    assert np.allclose(airtwin.stagnation_point(pan_deg, tilt_deg), (x, y), rtol=0, atol=1e-12)
    # The field's own stagnation point is the same eq. (2).
    assert np.allclose(airtwin.Field.default().stagnation_point(pan_deg, tilt_deg), (x, y),
                       rtol=0, atol=1e-12)


def test_the_origin_takes_the_pan_hint():
    assert airtwin.aim(0.0, 0.0, pan_hint_deg=45.0) == (45.0, 0.0)


def test_unreachable_raises_value_error_with_the_cli_reason():
    with pytest.raises(ValueError) as raised:
        airtwin.aim(5.0, 5.0)
    message = str(raised.value)
    assert message.startswith("unreachable: ")
    assert cli_error("aim", "--stagnation", "5,5").endswith(message)
    # A lower tilt limit shrinks the reachable disc.
    airtwin.aim(1.1, 1.1)
    with pytest.raises(ValueError, match="^unreachable: "):
        airtwin.aim(1.1, 1.1, max_tilt_deg=30.0)
    with pytest.raises(ValueError):
        airtwin.aim(0.1, 0.1, max_tilt_deg=95.0)
