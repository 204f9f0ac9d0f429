"""Timing of a measured closing from the closing foot, not the pelvis.

A closing (one foot's weight → both feet, ``support place``) arrives when
the free foot lands beside the other (DESIGN.md: a movement arrives at the
end of its duration; the virtual dancer's closing foot lands there).  The
pelvis travels only from over the standing foot to between the feet, a few
centimetres that a single-view fit smooths and delays: timed from it, the
closing was written half a beat to a beat late.  The closing foot itself
travels 10-30 cm and stops sharply, so its own progress times the closing.
"""

from __future__ import annotations

import numpy as np

__all__ = ["HOLD_SPEED", "MIN_CLOSE_TRAVEL_M", "START_TRAVEL_FRACTION", "closing_times"]

#: Least horizontal travel of a closing foot, metres, for it to time the
#: closing (less is fit wobble of a foot that was already beside the other).
MIN_CLOSE_TRAVEL_M = 0.04
#: A closing starts where its foot has covered this fraction of its travel
#: (a fitted foot creeps for half a beat before it really leaves).
START_TRAVEL_FRACTION = 0.15
#: A foot slower than this (m/s, horizontal) holds: the closing leaves from
#: its last hold (not from a free-leg gesture that arrived before it).
HOLD_SPEED = 0.05


def closing_times(foot: np.ndarray, contact: np.ndarray, since: int, a: int, fps: float):
    """Start and arrival of a measured closing from the closing foot, seconds.

    Parameters
    ----------
    foot : (T, 3) ndarray
        The closing foot's ankle, metres (smoothed).
    contact : (T,) ndarray of bool
        Its contact (smoothed joints: a sliding fitted foot is no contact
        until it stops).
    since : int
        Earliest frame the closing may start (where the previous support
        movement started: the run on one foot carries on through the
        closing while the foot slides).
    a : int
        First frame of the run on both feet.
    fps : float

    Returns
    -------
    (t0, t1) or None
        None when the landing is not found or the foot travels less than
        :data:`MIN_CLOSE_TRAVEL_M` from its start to its landing.

    Notes
    -----
    The arrival is the landing: the first frame of the contact run that
    carries into the run on both feet.  The closing leaves from the foot's
    last hold before it (slower than :data:`HOLD_SPEED`), from the point of
    that stretch farthest from the landing, and starts where it has covered
    :data:`START_TRAVEL_FRACTION` of its travel.
    """
    c = np.asarray(contact, bool)
    T = c.size
    if not (0 <= since < a < T) or not c[a]:
        return None
    land = a
    while land > since + 1 and c[land - 1]:
        land -= 1
    xy = np.asarray(foot, float)[:, :2]
    v = np.nan_to_num(np.linalg.norm(np.diff(xy, axis=0), axis=1), nan=0.0) * fps  # interval f: f → f + 1
    hold = land - 1
    while hold > since and v[hold] >= HOLD_SPEED:
        hold -= 1
    dist = np.linalg.norm(xy[hold : land + 1] - xy[land], axis=1)
    dist = np.nan_to_num(dist, nan=0.0)
    far = int(np.argmax(dist))
    travel = float(dist[far])
    if not travel >= MIN_CLOSE_TRAVEL_M:
        return None
    # The last frame still within the first fraction of the travel.
    left = np.flatnonzero(dist[far:] >= (1.0 - START_TRAVEL_FRACTION) * travel)
    start = hold + far + int(left[-1])
    return start / fps, land / fps
