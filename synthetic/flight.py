"""Flight: ``support air`` — take-off, a ballistic pelvis, touchdown and landing.

Semantics (DESIGN.md, "The score text format"; the staff draws flight as a
gap in the support column):

* ``support air`` over beats [a, b]: no foot bears weight on the frames
  strictly between; the feet on the floor at a leave it on the frame after
  (take-off), and the feet of the **landing** — the support symbols that
  start at b — touch the floor on frame(b) (touchdown), each at its
  target: its take-off spot for a foot that took off, else beside the
  take-off foot at standing width (a closing), moved one step length
  (:data:`~synthetic.supports.STEP_LENGTH`) in the landing's direction when
  it has one (a travelled spring; ``support`` may carry a direction here).
* The pelvis flies ballistically (gravity :data:`GRAVITY`) from its place at
  take-off — normally in plié, written by the support symbol before — to
  its touchdown height, where the landing legs are straight; horizontally it
  moves at a constant speed that the landing then brakes uniformly to rest
  over the mean of the landing feet.  The take-off is an impulse: the
  pelvis leaves the plié with its flight velocity (the push is not modelled;
  it lasts about a frame at 25 fps).
* The landing symbol [b, c] absorbs: the pelvis continues down at its
  touchdown velocity and comes to rest at c at the height its level asks
  (a plié for ``low``), following a cubic Hermite curve whose dip below that
  height is at most :data:`MAX_LANDING_DIP` (a steeper descent is slowed at
  touchdown instead).
* In the air, a foot that took off and lands again follows the pelvis,
  moving from its take-off place under the hip to its touchdown place, and
  points (:data:`POINTED_DEG`) at mid-flight; a foot that gestured before
  the take-off comes down from its gesture (the landing blend of
  :func:`synthetic.supports.leg_tracks`); a foot that took off and does not
  land keeps its leg's pose from the take-off (held, like any unnotated
  part) unless a gesture moves it, and stays clear of the floor.
"""

from __future__ import annotations

import numpy as np

from capture2notation.errors import SyntheticError
from capture2notation.notation.directions import canonical_vector

__all__ = ["GRAVITY", "MAX_LANDING_DIP", "POINTED_DEG", "TOUCHDOWN_REACH", "land", "plan_flight"]

#: Gravity, m/s².
GRAVITY = 9.81
#: Plantar flexion of a foot at mid-flight, degrees (a pointed foot, as in relevé).
POINTED_DEG = 35.0
#: Deepest the pelvis may sink below its landing height while absorbing, metres.
MAX_LANDING_DIP = 0.08
#: Fraction of the straight leg's reach at touchdown (nearly straight, so the
#: inverse kinematics keeps a defined knee plane).
TOUCHDOWN_REACH = 0.995

_FEET = {"support": ("right", "left"), "right_support": ("right",), "left_support": ("left",)}


def _other(foot: str) -> str:
    return "left" if foot == "right" else "right"


def _smooth(tau):
    tau = np.clip(tau, 0.0, 1.0)
    return tau * tau * (3.0 - 2.0 * tau)


def _pitch_clear(ankle_z: np.ndarray, toe: np.ndarray, clearance: float) -> np.ndarray:
    """(n,) the most pointed foot pitch (radians, negative points) keeping the toe `clearance` up.

    The toe at `toe` (3,) from the ankle in the foot's frame, the foot only
    pitched (``rot_x``): its height is ``ankle_z + R sin(p + φ)``.  Where no
    pitch can keep it there (the ankle itself too low), −π/2 (no limit).
    """
    ty, tz = float(toe[1]), float(toe[2])
    radius, phi = np.hypot(ty, tz), np.arctan2(tz, ty)
    need = (clearance - np.asarray(ankle_z, float)) / radius
    return np.where(np.abs(need) <= 1.0, np.arcsin(np.clip(need, -1.0, 1.0)) - phi, -np.pi / 2)


def plan_flight(sup, air, landings, before, xy: dict, level: dict) -> None:
    """Plan frames (frame(a), frame(b)] of flight `air` on the :class:`~synthetic.supports.Support` `sup`.

    Parameters
    ----------
    sup : Support
        Its ``root``, ``ankle``, ``pitch``, ``floor``, ``landing`` and
        ``released`` tracks are filled in place (plan coordinates).
    air : Symbol
        The ``support air`` symbol.
    landings : list of Symbol
        Support symbols starting where the flight ends (may be empty only
        when the flight ends the motion).
    before : list of str
        Feet on the floor at take-off.
    xy, level : dict
        Each foot's floor position (plan coordinates) and support level,
        updated for the landing feet.

    Raises
    ------
    SyntheticError
        A flight with motion after it but no landing.
    """
    frame, fps = sup.frame, sup.fps
    fa, fb = frame(air.start), frame(air.end)
    if fb <= fa:
        raise SyntheticError(f"support air at beat {air.start}: shorter than a frame at {fps:g} fps")
    if not landings and fb < sup.T - 1:
        raise SyntheticError(
            f"support air at beat {air.start}-{air.end} has no landing: a support symbol must start at beat {air.end}"
        )
    n = np.arange(fa + 1, fb + 1)
    t = (n - fa) / fps
    flight_s = (fb - fa) / fps
    root = sup.root
    targets: dict = {}
    for land_sym in landings:
        for foot in _FEET[land_sym.part]:
            other = _other(foot)
            if foot in before:
                base = xy[foot]
            elif other in before:
                base = xy[other] + (sup.hip_off[foot] - sup.hip_off[other])[:2]
            else:
                base = root[fa, :2] + sup.hip_off[foot][:2]
            target = base.copy()
            if land_sym.direction != "place":
                target = base + sup.step * canonical_vector(land_sym.direction, "middle")[:2]
            targets[foot] = (target, land_sym.level)
    if targets:
        key_xy = np.mean([tg for tg, _ in targets.values()], axis=0)
        brake_s = min((frame(s.end) - fb) / fps for s in landings)
    else:
        key_xy, brake_s = root[fa, :2].copy(), 0.0
    v_xy = (key_xy - root[fa, :2]) / (flight_s + brake_s / 2)
    xy_a, z_a = root[fa, :2].copy(), float(root[fa, 2])
    xy_td = xy_a + v_xy * flight_s
    z_td = z_a
    if targets:
        L = sup.leg_reach * TOUCHDOWN_REACH
        zs = []
        for foot, (tg, lv) in targets.items():
            h = np.linalg.norm(xy_td + sup.hip_off[foot][:2] - tg)
            zs.append(sup.level_z[lv] + np.sqrt(max(L * L - h * h, 0.0)))
        z_td = min(zs)
    v0 = (z_td - z_a) / flight_s + GRAVITY * flight_s / 2
    root[n, :2] = xy_a + t[:, None] * v_xy
    root[n, 2] = z_a + v0 * t - GRAVITY * t * t / 2
    root[fb + 1 :] = root[fb]
    sup.touchdown[fb] = np.r_[v_xy, v0 - GRAVITY * flight_s]

    tau = (n - fa) / (fb - fa)
    w = _smooth(tau)
    point = -np.radians(POINTED_DEG)
    for foot in ("right", "left"):
        ankle, pitch = sup.ankle[foot], sup.pitch[foot]
        if foot in targets:
            tg, lv = targets[foot]
            target = np.r_[tg, sup.level_z[lv]]
            pb = sup.level_pitch[lv]
            if foot in before:
                # Carried by the leg from under the hip at take-off to touchdown.
                off_a = ankle[fa] - root[fa]
                off_b = target - root[fb]
                ankle[n] = root[n] + (1.0 - w)[:, None] * off_a + w[:, None] * off_b
                base = (1.0 - w) * pitch[fa] + w * pb
                pitch[n] = base + (point - base) * np.sin(np.pi * tau) ** 2
                # A low flight has no room for a fully pointed foot: the toe
                # would brush the floor at the top and the dancer would be
                # seen landing mid-air.  It points only as far as keeps it
                # clear, like a gesturing foot's (Support.toe_clearance).
                aloft = n[:-1]  # every frame but the touchdown's
                pitch[aloft] = np.maximum(
                    pitch[aloft], _pitch_clear(ankle[aloft, 2], sup.toe_offset, sup.toe_clearance)
                )
                sup.floor[foot][n] = True
            else:
                # Down from a gesture (the landing blend of leg_tracks).
                ankle[n] = target
                pitch[n] = pb
                sup.landing[foot][n] = True
                sup.floor[foot][n] = True
            ankle[fb + 1 :] = target
            pitch[fb + 1 :] = pb
            xy[foot], level[foot] = tg, lv
        elif foot in before:
            # Off the floor for good: the leg holds its take-off pose until its next symbol.
            nxt = [x.start for x in sup.foot_symbols(foot) if x.start >= air.start]
            stop = sup.T - 1 if not nxt else frame(min(nxt))
            sup.released[foot][fa + 1 : stop + 1] = True
            sup.floor[foot][fa + 1 : stop + 1] = False


def land(sup, sym, key: np.ndarray) -> None:
    """Absorb a landing `sym`: the pelvis from touchdown to rest at `key` (plan coordinates).

    Parameters
    ----------
    sup : Support
    sym : Symbol
        The landing support symbol (starts where a flight ends).
    key : (3,) ndarray
        Pelvis position at rest at the end of `sym`.
    """
    f0, f1 = sup.frame(sym.start), sup.frame(sym.end)
    if f1 <= f0:
        sup.root[f0:] = key
        return
    n = np.arange(f0 + 1, f1 + 1)
    s = (n - f0) / (f1 - f0)
    D = (f1 - f0) / sup.fps
    p0, v = sup.root[f0].copy(), sup.touchdown.get(f0, np.zeros(3))
    h00, h10, h01 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2
    # The dip below the landing height is bounded: a steeper descent is slowed at touchdown.
    m_z = v[2] * D
    for _ in range(30):
        z = h00 * p0[2] + h10 * m_z + h01 * key[2]
        if z.min() >= key[2] - MAX_LANDING_DIP or abs(m_z) < 1e-6:
            break
        m_z *= 0.8
    sup.root[n, :2] = h00[:, None] * p0[:2] + h10[:, None] * (v[:2] * D) + h01[:, None] * key[:2]
    sup.root[n, 2] = h00 * p0[2] + h10 * m_z + h01 * key[2]
    sup.root[f1:] = key
