"""The solver's model: FK agrees with the body package; analytic Jacobian agrees with finite differences."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from capture2notation.body import JOINTS, Body, forward_kinematics
from capture2notation.fitting import PoseModel


def _random_params(model, seed, T=3):
    rng = np.random.default_rng(seed)
    p = rng.normal(0.0, 0.6, (T, model.n_params))
    p[:, :3] = rng.normal(0.0, 1.0, (T, 3))
    return p


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000), height=st.floats(1.2, 2.1))
def test_joints_match_forward_kinematics(seed, height):
    body = Body(height)
    model = PoseModel(body)
    p = _random_params(model, seed)
    pts = model.forward(p)
    fk = forward_kinematics(model.angles(p), p[:, :3], body)
    np.testing.assert_allclose(pts[:, : len(JOINTS)], fk, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_jacobian_matches_finite_differences(seed):
    model = PoseModel(Body())
    p = _random_params(model, seed)
    pts, jac = model.forward(p, jacobian=True)
    eps = 1e-6
    num = np.empty_like(jac)
    for d in range(model.n_params):
        q = p.copy()
        q[:, d] += eps
        num[..., d] = (model.forward(q) - pts) / eps
    np.testing.assert_allclose(jac, num, atol=2e-5)


def test_params_round_trip_and_locked_axes_stay_zero():
    body = Body()
    model = PoseModel(body)
    p = _random_params(model, 5)
    ang = model.angles(p)
    np.testing.assert_array_equal(model.params(ang, p[:, :3]), p)
    locked = body.limits[..., 1] <= body.limits[..., 0]
    locked[0] = False
    assert np.all(ang[:, locked] == 0.0)


def test_per_clip_offsets_scale_virtual_points():
    body = Body()
    model = PoseModel(body, body.offsets * 1.1)
    rest = model.forward(np.zeros((1, model.n_params)))[0]
    base = PoseModel(body).forward(np.zeros((1, model.n_params)))[0]
    neck = model.index("neck")
    for name in ("nose", "left_ear", "head_centre"):
        i = model.index(name)
        np.testing.assert_allclose(rest[i] - rest[neck], 1.1 * (base[i] - base[neck]), atol=1e-12)
