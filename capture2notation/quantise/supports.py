"""Support symbols: which feet carry the weight, at which level, and steps.

Per frame (DESIGN.md): a foot is *in contact* when it is within 3 cm of the
floor and slower than 0.2 m/s (:func:`~.labels.support_frames`).  Of the
feet in contact, those that carry the weight are found from the pelvis: with
both feet down, a pelvis over one foot (within a quarter of the way to the
other) puts the weight on that foot alone, otherwise on both.  The support
*part* is ``support`` (both), ``right_support`` or ``left_support``; its
level is that of the weight-bearing feet (low: knee bent > 30°, high: heel
raised; the lower of two unequal levels).

Support movements are found like gestures (:func:`~.segment.movement_spans`)
on a "support speed": the pelvis's speed in leg lengths (expressed in
degrees per second, as an angle seen from the foot) plus the hip-ankle
length and foot-pitch speeds of the weight-bearing feet.  Back-to-back
support movements part at grid frames where both feet are down and the
speed has a deep minimum, or where a foot lands (a step or a closing
arrives when its foot comes down, even with the other foot free).  Each
movement whose end state differs from the state before it becomes one symbol; its direction is
``place`` unless a weight-bearing foot travelled more than half a step
(0.09 body heights) from under its hip — then the sector of that travel in
the body frame (a step).

Measured motion (fitted joints, mocap) is segmented from runs of its support
state instead: :mod:`.supports_measured`.  The per-frame reading both share
is :mod:`.support_state`.
"""

from __future__ import annotations

import numpy as np

from ..body import joint_index
from ..notation.directions import bend_angle
from ..notation.model import LEVELS
from .labels import FrameLabels
from .movement import Movement
from .support_state import (
    NOISY_POSITION_M,
    SUPPORT_PARTS,
    body_height,
    position_noise,
    step_direction,
    support_speed,
    support_state,
)
from .supports_measured import measured_support_movements

__all__ = ["support_movements"]


def support_movements(
    labels: FrameLabels,
    joints: np.ndarray,
    fps: float,
    params,
    spans_fn,
    on_grid: np.ndarray | None = None,
    measured: bool = False,
    turn_ends: np.ndarray | None = None,
    take_offs: np.ndarray | None = None,
) -> list:
    """Support movements as :class:`~.segment.Movement` objects (see the module docstring).

    Noisy motion (jitter above :data:`NOISY_POSITION_M`, or `measured`:
    fitted or recorded, never exactly still however smooth): see
    :func:`measured_support_movements`; `labels` should then carry the contacts
    of smoothed joints (:func:`smooth_positions`, as
    :func:`~.segment.segment_motion` does).  `turn_ends` (T,) bool, clean
    motion: frames where a turn arrives, where a support on one foot may
    part too (a pirouette's relevé ends with its turn).  `take_offs` (T,)
    bool, clean motion: the first frame of each flight
    (:func:`~.flight.find_flights`), where the support sprung from arrives
    (its span would otherwise run on to the landing).
    """

    T = joints.shape[0]
    if measured or position_noise(joints) > NOISY_POSITION_M:
        return measured_support_movements(labels, joints, fps)
    part, level = support_state(labels, joints)
    speed = support_speed(labels, joints, fps)
    # Clean motion: any motion is a movement; back-to-back support
    # symbols part at grid frames with both feet down and the speed at a
    # local minimum (never mid-step, while a foot is in the air).
    knees = np.stack(
        [
            bend_angle(
                joints[:, joint_index(f"{side}_hip")],
                joints[:, joint_index(f"{side}_knee")],
                joints[:, joint_index(f"{side}_ankle")],
            )
            for side in ("right", "left")
        ],
        axis=1,
    )
    spans = spans_fn(
        speed,
        1e-4,
        2e-4,
        params.split_ratio,
        key_pose=_support_cut_fn(labels, speed, on_grid, knees, fps, turn_ends, take_offs),
    )
    height = body_height(joints)
    state = (0, LEVELS.index("middle"), "place")
    out = []
    for a, b in spans:
        end = min(b + 1, T - 1)
        # The state where the movement settles: the end frame, or the next
        # grounded one if the dancer is still in the air there.
        k = end
        while k < T - 1 and part[k] < 0:
            k += 1
        if part[k] < 0:
            continue
        bearing = (state[0] in (0, 1), state[0] in (0, 2))  # the feet of the support before
        direction = step_direction(joints, labels, a, k, part[k], height, bearing=bearing)
        new = (int(part[k]), int(level[k]), direction)
        if new == state:
            continue
        state = new
        out.append(Movement(SUPPORT_PARTS[new[0]], a, end, a / fps, (b + 1) / fps, direction, LEVELS[new[1]], 0))
    return out


def _support_cut_fn(
    labels: FrameLabels,
    speed: np.ndarray,
    on_grid: np.ndarray | None,
    knees=None,
    fps: float = 25.0,
    turn_ends: np.ndarray | None = None,
    take_offs: np.ndarray | None = None,
):
    """``(f, since) -> bool`` for :func:`~.segment.movement_spans`: frame f may part two support movements.

    Either a foot lands at f (it supports at f and did not at f - 1), or
    both feet are down and the speed has a deep local minimum there.
    `knees` (T, 2), degrees: knee bends.  Knees that straighten exactly and
    bend again at f (a kink, not a speed minimum: the bend cannot go below
    0) mark the arrival at a straight-legged support between two others.
    """
    sup = labels.supporting
    down = sup.all(axis=1)
    # A foot that lands at f (a step, a closing) arrives there, whatever the
    # other foot does: after a step onto one foot the other is free.
    landed = np.zeros(len(sup), bool)
    landed[1:] = (sup[1:] & ~sup[:-1]).any(axis=1)
    n = speed.size

    def key(f: int, since: int) -> bool:
        if on_grid is not None and not on_grid[f]:
            return False
        if landed[f] or (take_offs is not None and take_offs[f]):
            return True
        if not down[f] and not (turn_ends is not None and turn_ends[f] and sup[f].any()):
            return False
        if knees is not None and 0 < f < len(knees) - 1:
            k = knees[f - 1 : f + 2]
            if np.all(k[1] < 0.05) and np.all(k[0] > k[1] + 0.1) and np.all(k[2] > k[1] + 0.1):
                return True
        # A deep local speed minimum in the interval just before or after f
        # (below a third of the peaks within two seconds on either side:
        # a slow plié peaks early and arrives slowly, over a second before
        # its end).
        w = max(2, int(round(2.0 * fps)))
        for m in (f - 1, f):
            if 0 < m < n - 1 and speed[m] <= speed[m - 1] and speed[m] <= speed[m + 1]:
                left, right = speed[max(0, m - w) : m].max(), speed[m + 1 : m + 1 + w].max()
                if speed[m] <= 0.35 * min(left, right):
                    return True
        return False

    key.on_grid = on_grid is not None
    return key
