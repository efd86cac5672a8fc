"""airtwin.predict (eqs. 8-9) against the CVODE reference, a NumPy integration of the defining
equations on the bound field, and itself (objects are independent lanes)."""

import numpy as np
import pytest

import airtwin

FIELD = airtwin.Field.default()
TRACER = airtwin.object_dynamics("tracer")
PAN_DEG, TILT_DEG = 30.0, 20.0


def starts(n, seed=11):
    """n objects within 0.25 m of the stagnation point, at rest."""
    s = np.array(FIELD.stagnation_point(PAN_DEG, TILT_DEG))
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, n)
    radius = rng.uniform(0.02, 0.25, n)
    return s + radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])


def test_shipped_object_types_are_the_papers():
    assert TRACER == (-2.66, 4.26, -8.53)
    assert airtwin.object_dynamics("cotton") == (-4.25, 3.46, -4.12)
    with pytest.raises(ValueError, match="tracer"):
        airtwin.object_dynamics("pebble")


def test_fast_predictor_agrees_with_cvode():
    positions = starts(40)
    xi = np.tile(TRACER, (40, 1))
    fast = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi)
    cvode = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, method="cvode")
    moved = np.hypot(*(fast.end[:, :2] - positions).T)
    assert np.max(moved) > 0.1  # the jet moves them
    # docs/dynamics.md: <= 0.35 mm near s
    assert np.max(np.abs(fast.end[:, :2] - cvode.end[:, :2])) < 3.5e-4


def test_prediction_follows_eqs_8_and_9_integrated_in_numpy():
    positions = starts(12, seed=2)
    xi1, xi2, xi3 = TRACER
    s = np.array(FIELD.stagnation_point(PAN_DEG, TILT_DEG))
    horizon_s, dt = 0.8, 1e-3

    def rate(p, v):
        air = FIELD.velocity(PAN_DEG, TILT_DEG, p)
        u = (p - s) / np.hypot(*(p - s).T)[:, None]  # eq. (9): radial from s
        return v[:, None] * u, xi1 * v + xi2 * np.hypot(*air.T) + xi3  # eq. (8)

    p, v = positions.copy(), np.zeros(len(positions))
    moving = np.hypot(*FIELD.velocity(PAN_DEG, TILT_DEG, p).T) * xi2 + xi3 > 0
    for _ in range(round(horizon_s / dt)):
        k1 = rate(p, v)
        k2 = rate(p + 0.5 * dt * k1[0], v + 0.5 * dt * k1[1])
        k3 = rate(p + 0.5 * dt * k2[0], v + 0.5 * dt * k2[1])
        k4 = rate(p + dt * k3[0], v + dt * k3[1])
        p_next = p + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v_next = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        moving &= v_next > 0  # a stop is for good under one orientation
        p = np.where(moving[:, None], p_next, p)
        v = np.where(moving, v_next, 0.0)
    predicted = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, np.tile(TRACER, (12, 1)),
                                horizon_s=horizon_s)
    assert np.max(np.hypot(*(predicted.end[:, :2] - p).T)) < 1e-3
    assert np.max(np.abs(predicted.end[:, 2] - v)) < 1e-2


def test_objects_are_independent_lanes():
    positions = starts(9, seed=4)
    xi = np.tile(TRACER, (9, 1))
    xi[::2] = airtwin.object_dynamics("cotton")
    speeds = np.linspace(0.0, 0.4, 9)
    batch = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, speeds=speeds)
    for j in range(9):
        alone = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions[j:j + 1], xi[j:j + 1],
                                speeds=speeds[j:j + 1])
        assert np.array_equal(alone.end, batch.end[j:j + 1])
        assert np.array_equal(alone.rest_since_s, batch.rest_since_s[j:j + 1])


def test_a_schedule_equals_its_segments_one_after_the_other():
    positions = starts(6, seed=9)
    xi = np.tile(TRACER, (6, 1))
    whole = airtwin.predict(FIELD, [PAN_DEG, -60.0], [TILT_DEG, 35.0], positions, xi,
                            horizon_s=1.5, t_start_s=[0.0, 0.5])
    first = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, horizon_s=0.5)
    second = airtwin.predict(FIELD, -60.0, 35.0, first.end[:, :2], xi, speeds=first.end[:, 2],
                             horizon_s=1.0)
    assert np.allclose(whole.end, second.end, rtol=0, atol=1e-12)


def test_samples_are_read_only_views_that_outlive_the_prediction():
    positions = starts(5)
    prediction = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, np.tile(TRACER, (5, 1)),
                                 horizon_s=1.0, sample_rate_hz=40.0)
    times, samples, end = prediction.sample_times_s, prediction.samples, prediction.end
    assert times.shape == (41,) and samples.shape == (41, 5, 3) and end.shape == (5, 3)
    assert np.array_equal(times, np.arange(41) / 40.0)
    assert np.array_equal(samples[0, :, :2], positions) and not samples[0, :, 2].any()
    assert np.array_equal(samples[-1], end)
    assert not samples.flags.writeable and not end.flags.writeable
    assert not samples.flags.owndata  # a view of the C++ result
    del prediction
    assert np.array_equal(samples[-1], end)
    no_samples = airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, np.tile(TRACER, (5, 1)))
    assert no_samples.samples.shape == (0, 5, 3) and no_samples.sample_times_s.shape == (0,)


def test_bad_input_raises_value_error_with_the_library_message():
    positions = starts(3)
    xi = np.tile(TRACER, (3, 1))
    with pytest.raises(ValueError, match=r"^trajectory prediction: object 1: eq. \(8\) coef"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions,
                        np.array([TRACER, (np.nan, 4.26, -8.53), TRACER]))
    with pytest.raises(ValueError, match=r"^trajectory prediction: object 2: speed must be"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, speeds=[0.0, 0.1, -0.1])
    with pytest.raises(ValueError, match=r"^trajectory prediction: horizon must be finite"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, horizon_s=-1.0)
    with pytest.raises(ValueError, match=r"^dynamics: expected one row"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi[:2])
    with pytest.raises(ValueError, match=r"^speeds: expected a vector of 3 values"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, speeds=[0.0])
    with pytest.raises(ValueError, match=r"^pan_deg, tilt_deg: expected 2 values each"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, t_start_s=[0.0, 0.5])
    with pytest.raises(ValueError, match=r"^orientation schedule: entry 1"):
        # 89 deg: beyond the fold of eq. (2) with the default model's a1, a2 (88.7 deg).
        airtwin.predict(FIELD, [0.0, 0.0], [10.0, 89.0], positions, xi, t_start_s=[0.0, 0.5])
    with pytest.raises(ValueError, match=r"^method: expected fast or cvode, got 'euler'$"):
        airtwin.predict(FIELD, PAN_DEG, TILT_DEG, positions, xi, method="euler")
