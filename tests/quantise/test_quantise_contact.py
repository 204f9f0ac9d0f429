"""Feet on the floor by Viterbi over measured motion (:mod:`capture2notation.quantise.contact`)."""

import numpy as np

from capture2notation.body import Body, joint_index
from capture2notation.quantise.contact import MAX_FLOOR_OFFSET_M, MIN_HEIGHT_SD_M, decode_contacts
from capture2notation.quantise.labels import support_frames

FPS = 100.0


def _standing(T: int, rng: np.random.Generator, jitter: float) -> np.ndarray:
    p = np.repeat(Body().rest[None], T, axis=0).copy()
    return p + rng.normal(0, jitter, p.shape)


def _lift(p: np.ndarray, side: str, a: int, b: int, height: float) -> None:
    T = b - a
    bump = np.sin(np.linspace(0, np.pi, T)) * height
    for part in ("ankle", "toe", "knee"):
        p[a:b, joint_index(f"{side}_{part}"), 2] += bump


def test_a_step_lifts_one_foot_and_mocap_jitter_does_not():
    rng = np.random.default_rng(1)
    p = _standing(400, rng, 0.002)  # 2 mm at 100 fps: 0.3-0.4 m/s frame to frame
    _lift(p, "right", 150, 190, 0.12)  # a step's flight: 0.4 s, 12 cm
    c = decode_contacts(p, FPS)
    # The per-frame rule (DESIGN.md: slower than 0.2 m/s) loses the standing feet to jitter.
    naive, _ = support_frames(p, FPS)
    assert naive.mean() < 0.6
    assert c[:140].all() and c[200:].all()  # both feet stand
    assert not c[160:180, 0].any() and c[:, 1].all()  # the right foot flies, the left stays


def test_an_unseen_foot_never_supports():
    rng = np.random.default_rng(2)
    p = _standing(200, rng, 0.002)
    seen = np.ones((200, 2), bool)
    seen[:, 1] = False  # the left foot is out of frame
    c = decode_contacts(p, FPS, seen=seen)
    assert c[:, 0].all() and not c[:, 1].any()


def test_a_foot_brushing_the_floor_fast_is_not_on_it():
    rng = np.random.default_rng(3)
    p = _standing(300, rng, 0.001)
    # A brush: the free foot sweeps forward 0.6 m in 0.3 s at 1 cm above the floor.
    a, b = 100, 130
    for part in ("ankle", "toe"):
        p[a:b, joint_index(f"right_{part}"), 1] += np.linspace(0, 0.6, b - a)
        p[b:, joint_index(f"right_{part}"), 1] += 0.6
        p[a:b, joint_index(f"right_{part}"), 2] += 0.01
    c = decode_contacts(p, FPS)
    assert not c[105:125, 0].any() and c[:, 1].all()


def test_a_foot_landing_on_the_last_frames_is_on_the_floor():
    """The clip ends as a foot lands: after the clip the body holds its pose
    (DESIGN.md), so the landing is decoded like any other, as the per-frame
    rule reads it; a foot still in the air at the end stays in the air."""
    rng = np.random.default_rng(4)
    p = _standing(300, rng, 0.001)
    _lift(p, "right", 160, 240, 0.12)  # lifted for 0.8 s, down again on frame 239
    c = decode_contacts(p[:240], FPS)  # the clip ends on the frame the foot lands
    assert c[-1, 0] and c[:150].all() and not c[180:220, 0].any()
    mid_air = decode_contacts(p[:195], FPS)  # ends near the top of the lift, 12 cm up
    assert not mid_air[-1, 0] and mid_air[:, 1].all()


def test_feet_far_above_the_floor_are_in_the_air():
    """Feet that never come within a few centimetres of the floor (a floor
    guessed 10 cm low) are not stretched onto it: the height spread a stance
    may have is capped (:data:`~capture2notation.quantise.contact.MAX_HEIGHT_SD_M`)."""
    rng = np.random.default_rng(5)
    p = _standing(300, rng, 0.002)
    p[..., 2] += 0.10
    assert not decode_contacts(p, FPS).any()
    p[..., 2] -= 0.10
    assert decode_contacts(p, FPS).all()


def test_a_stance_the_fit_lifts_by_centimetres_stays_on_the_floor():
    """A fitted foot's points drift above the sole it stands on (BlazePose's
    ankle and toe, the body model's foot): the grounded level is the clip's
    own, fitted by the decoder, within :data:`MAX_FLOOR_OFFSET_M`."""
    rng = np.random.default_rng(11)
    fps, T = 25.0, 300
    p = _standing(T, rng, 0.0)
    for part in ("ankle", "toe"):
        p[:, joint_index(f"right_{part}"), 2] += np.linspace(0.0, 0.05, T)  # 0 -> 5 cm over 12 s
        p[:, joint_index(f"left_{part}"), 2] += 0.025
    _lift(p, "left", 120, 280, 0.3)  # the other leg gestures meanwhile
    p += rng.normal(0, 0.006, p.shape)
    c = decode_contacts(p, fps)
    assert c[:, 0].all()
    assert c[:115, 1].all() and c[285:, 1].all() and not c[140:260, 1].any()


def test_a_foot_held_a_hand_above_the_floor_is_not_on_it():
    # A low gesture held still, 8 cm up, while the other foot stands: above
    # the highest grounded level believed by more than three of this clip's
    # grounded scatter (4 mm jitter: the least scatter, MIN_HEIGHT_SD_M).
    held = 0.08
    assert held - MAX_FLOOR_OFFSET_M > 3 * MIN_HEIGHT_SD_M
    rng = np.random.default_rng(12)
    fps, T = 25.0, 300
    p = _standing(T, rng, 0.004)
    for part in ("ankle", "toe", "knee"):
        p[100:200, joint_index(f"right_{part}"), 2] += held
    c = decode_contacts(p, fps)
    assert not c[105:195, 0].any() and c[:95, 0].all() and c[:, 1].all()
