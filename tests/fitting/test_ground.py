"""The floor of a motion file from its lowest foot points (:mod:`capture2notation.fitting.ground`)."""

import numpy as np

from capture2notation.body import Body, joint_index
from capture2notation.fitting.ground import fit_floor, level_points

FPS = 50.0


def _walker(T: int, rng: np.random.Generator, hop: bool = False) -> np.ndarray:
    """The rest pose walking to and fro along x (±1.5 m, 6 s a round), one foot lifted in turn.

    To and fro: a drift linear in time along a straight walk is a tilt (nothing tells them apart).
    """
    rest = Body().rest
    p = np.repeat(rest[None], T, axis=0).copy()
    t = np.arange(T) / FPS
    p[..., 0] += (1.5 * np.sin(2 * np.pi * t / 6.0))[:, None]
    for side, phase in (("right", 0.0), ("left", np.pi)):
        lift = np.clip(np.sin(2 * np.pi * t + phase), 0, None) * 0.12
        for part in ("ankle", "toe"):
            p[:, joint_index(f"{side}_{part}"), 2] += lift
    if hop:  # both feet off the floor a fifth of the time
        air = (np.arange(T) % 50) < 10
        p[air, :, 2] += 0.3
    return p + rng.normal(0, 0.003, p.shape)


def test_a_tilted_offset_floor_is_levelled_to_z_0():
    rng = np.random.default_rng(3)
    p = _walker(500, rng)
    # A sensor pitched 8° and 1.1 m above the floor (Kinect-like).
    a = np.radians(8.0)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    seen = p @ R.T + [0.0, 0.0, -1.1]
    fit = fit_floor(seen, np.ones(p.shape[:2], bool), FPS)
    assert abs(fit.tilt_deg - 8.0) < 0.5
    back = level_points(seen, fit)
    toe = back[:, joint_index("right_toe"), 2] - Body().rest[joint_index("right_toe"), 2]
    # Standing frames sit on the floor within the jitter (DESIGN.md support height 3 cm).
    assert abs(np.median(np.sort(toe)[: len(toe) // 3])) < 0.01


def test_a_drifting_floor_is_followed_and_a_hop_does_not_lift_it():
    rng = np.random.default_rng(4)
    p = _walker(600, rng, hop=True)
    drift = np.linspace(0.0, 0.25, 600)  # inertial root drift, 25 cm over 12 s
    seen = p.copy()
    seen[..., 2] += drift[:, None]
    fit = fit_floor(seen, np.ones(p.shape[:2], bool), FPS)
    assert fit.drifts and fit.tilt_deg == 0.0
    # Against the true drift: within 2 cm away from the clip's ends.
    assert np.max(np.abs(fit.height - drift)[100:-100]) < 0.02


def test_a_level_floor_is_one_constant_height():
    rng = np.random.default_rng(5)
    p = _walker(300, rng)
    p[..., 2] += 0.94
    fit = fit_floor(p, np.ones(p.shape[:2], bool), FPS)
    assert not fit.drifts and np.ptp(fit.height) == 0.0
    assert abs(fit.height[0] - 0.94) < 0.01


def test_a_video_fits_floor_is_where_its_scattered_feet_stand():
    """A fitted dancer's feet scatter ~3 cm about the floor they stand on
    (depth and pose errors), and hop off it a fifth of the time.  Without a
    time axis (a video fit, ``fps=None``) the floor is the grounded points'
    mean: within 1 cm of the true floor, where a low quantile (the 20th
    percentile) sits 0.84 of the scatter, 2.5 cm, below it and leaves every
    standing foot floating."""
    rng = np.random.default_rng(6)
    p = _walker(600, rng, hop=True)
    scatter = rng.normal(0.0, 0.03, 600)
    p[..., 2] += 0.7 + scatter[:, None]
    fit = fit_floor(p, np.ones(p.shape[:2], bool), None, tilt=False)
    assert not fit.drifts and fit.tilt_deg == 0.0
    assert abs(float(np.median(fit.height)) - 0.7) < 0.01
