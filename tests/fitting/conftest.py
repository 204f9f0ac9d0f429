"""Synthetic observations of known poses for the fitting tests (as the `synth` fixture)."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.body import JOINTS, Body, joint_index
from capture2notation.fitting import Camera, PoseModel
from capture2notation.fitting.fit import TARGETS_2D

# (joint, axis, amplitude rad, one-sided): smooth swings of arms, legs, trunk.
_SWINGS = (
    ("right_shoulder", 0, 1.5, True),
    ("right_shoulder", 1, -1.2, True),
    ("left_shoulder", 0, 1.2, True),
    ("left_shoulder", 1, 1.0, True),
    ("right_elbow", 0, 1.2, True),
    ("left_elbow", 0, 1.0, True),
    ("right_hip", 0, 0.8, True),
    ("left_hip", 1, 0.4, True),
    ("right_knee", 0, -1.0, True),
    ("left_knee", 0, -0.6, True),
    ("waist", 0, 0.3, False),
    ("neck", 0, 0.3, False),
    ("pelvis", 2, 0.8, False),
)


def make_motion(T: int, seed: int, fps: float = 25.0, body: Body | None = None):
    """Angles (T, J, 3) and root (T, 3) of a smooth random dance (within limits)."""
    rng = np.random.default_rng(seed)
    body = body or Body()
    t = np.arange(T) / fps
    ang = np.zeros((T, len(JOINTS), 3))
    for name, ax, amp, one_sided in _SWINGS:
        phase, freq = rng.uniform(0, 2 * np.pi), rng.uniform(0.2, 0.6)
        wave = np.sin(2 * np.pi * freq * t + phase)
        ang[:, joint_index(name), ax] = amp * 0.5 * (1 + wave) if one_sided else amp * wave
    root = np.tile(body.rest[0], (T, 1))
    root[:, 0] += 0.3 * np.sin(t)
    return body.clip(ang), root


def held_pose(T: int, body: Body, **angles):
    """Angles (T, J, 3) and root (T, 3) of a standing figure with some joints held at given Euler angles."""
    ang = np.zeros((T, len(JOINTS), 3))
    for name, value in angles.items():
        ang[:, joint_index(name)] = value
    return body.clip(ang), np.tile(body.rest[0], (T, 1))


def observe(angles, root, camera: Camera, body: Body | None = None, noise_px: float = 0.0, seed: int = 0):
    """BlazePose-like observations of a pose: (xy (T,33,2), conf (T,33), world (T,33,3), joints (T,J,3))."""
    body = body or Body()
    rng = np.random.default_rng(seed)
    m = PoseModel(body)
    pts = m.forward(m.params(angles, root))
    T = len(angles)
    xy = np.full((T, 33, 2), np.nan)
    conf = np.zeros((T, 33))
    world = np.full((T, 33, 3), np.nan)
    for name, lms, _ in TARGETS_2D:
        if len(lms) != 1:
            continue
        p = pts[:, m.index(name)]
        xy[:, lms[0]] = camera.project(p) + rng.normal(0.0, noise_px, (T, 2))
        conf[:, lms[0]] = 1.0
        world[:, lms[0]] = (p - root) @ camera.R.T
    return xy, conf, world, pts[:, : len(JOINTS)]


def limb_direction_errors(joints, truth) -> np.ndarray:
    """Angles (degrees) between fitted and true limb segments, all frames and limbs."""
    out = []
    for side in ("right", "left"):
        for a, b in (("shoulder", "elbow"), ("elbow", "wrist"), ("hip", "knee"), ("knee", "ankle")):
            ia, ib = joint_index(f"{side}_{a}"), joint_index(f"{side}_{b}")
            u = truth[:, ib] - truth[:, ia]
            v = joints[:, ib] - joints[:, ia]
            cos = np.sum(u * v, -1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
            out.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    return np.concatenate(out)


# The test modules are imported with --import-mode=importlib, so the helpers
# reach them as a fixture rather than an import.
@pytest.fixture(scope="session")
def synth():
    """The helpers above: ``synth.make_motion``, ``synth.observe``, ``synth.limb_direction_errors``."""
    from types import SimpleNamespace

    return SimpleNamespace(
        make_motion=make_motion, held_pose=held_pose, observe=observe, limb_direction_errors=limb_direction_errors
    )
