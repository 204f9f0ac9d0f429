"""Turns: the dancer's front over time and its place in the room.

The supports, legs and gestures are planned in **plan coordinates**, in
which the dancer always faces +y (:mod:`synthetic.supports`); steps there
go forward, sideways or back, so they travel relative to the current front
once placed in the room.  Turns place the plan in the room by a rigid motion
about the vertical that changes only while a turn is in progress:

* the front (the pelvis's yaw) follows each turn symbol with the Effort
  progress ``s(τ)`` over its span, clockwise for ``right``;
* a turn on the floor pivots about its **pivot**: the centre (midpoint of
  ankle and toe, DESIGN.md's support point) of the supporting foot, or the
  midpoint of both feet's centres on two feet — the feet bearing weight at
  the turn's end, so a pirouette that rises from two feet onto one turns
  on that one.  The pivot follows the centre as the foot rises into relevé
  or lowers, so a supporting foot's centre moves only as it would without
  the turn: the foot spins on the spot and keeps reading as supporting.  On
  two feet both feet slide round their midpoint (keep such turns slow: a
  foot faster than 0.2 m/s no longer reads as supporting);
* a turn in the air (overlapping ``support air``) pivots about the pelvis,
  which keeps flying straight along the front it took off with.

Everything the plan holds — pelvis, feet, the whole figure — is moved by
the same rigid motion, so joint angles below the pelvis do not change: the
pelvis's yaw carries the turn.
"""

from __future__ import annotations

import numpy as np

from capture2notation.notation.effort import progress

__all__ = ["front_track", "place_in_room", "turn_spans"]


def turn_spans(symbols, frame) -> list:
    """``(symbol, f0, f1)`` of every turn, in time order."""
    return [(s, frame(s.start), frame(s.end)) for s in symbols if s.is_turn]


def front_track(symbols, frame, T: int, eff) -> np.ndarray:
    """(T,) front, radians clockwise seen from above from the starting front (unwrapped).

    Each turn adds its signed amount × 2π over frames (f0, f1] with the
    Effort progress ``s(τ)`` (time `eff.time`, weight `eff.weight`).
    """
    yaw = np.zeros(T)
    for s, f0, f1 in turn_spans(symbols, frame):
        total = float(s.signed_amount) * 2.0 * np.pi
        n = np.arange(f0 + 1, min(f1, T - 1) + 1)
        if f1 > f0:
            yaw[n] += total * progress((n - f0) / (f1 - f0), eff.time, eff.weight)
        yaw[f1 + 1 :] += total
    return yaw


def _rot(theta: np.ndarray) -> np.ndarray:
    """(n, 2, 2) counter-clockwise rotations by `theta` radians."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def place_in_room(root: np.ndarray, front: np.ndarray, turns: list) -> np.ndarray:
    """Pelvis positions in the room from the plan's, given the front and each turn's pivot.

    Parameters
    ----------
    root : (T, 3) ndarray
        Pelvis in plan coordinates, metres.
    front : (T,) ndarray
        :func:`front_track`, radians clockwise.
    turns : list of (int, int, (T, 2) ndarray or None)
        ``(f0, f1, pivot)`` of each turn in time order: the pivot's track in
        plan coordinates, or None to pivot about the pelvis (in the air).

    Returns
    -------
    (T, 3) ndarray
        The pelvis in the room.  With the pelvis turned by ``front`` (its
        rz = −front), every point of the figure lands where this rigid
        motion takes its plan position.
    """
    T = len(root)
    theta = -np.asarray(front, float)  # counter-clockwise, as rz
    shift = np.zeros((T, 2))
    current = np.zeros(2)
    done = 0
    for f0, f1, pivot in turns:
        shift[done : f0 + 1] = current
        f1 = min(f1, T - 1)
        n = np.arange(f0 + 1, f1 + 1)
        if n.size:
            p = root[n, :2] if pivot is None else np.asarray(pivot, float)[n]
            before = _rot(np.full(n.size, theta[f0]))
            delta = _rot(theta[n] - theta[f0])
            # world = R(θ0)(p + R(Δ)(x − p)) + T0 = R(θ) x + [T0 + R(θ0)(p − R(Δ) p)]
            shift[n] = current + np.einsum("nij,nj->ni", before, p - np.einsum("nij,nj->ni", delta, p))
            current = shift[f1].copy()
        done = f1 + 1
    shift[done:] = current
    out = root.copy()
    out[:, :2] = np.einsum("nij,nj->ni", _rot(theta), root[:, :2]) + shift
    return out
