"""Where the emotion presets mean something: the domain of a ballet port de bras.

Neagle's presets (happy, sad, angry, afraid; :data:`~..notation.effort.PRESETS`)
were measured on a port de bras performed with an emotion: the dancer stands
in place on both feet, the arms lead phrases of one-beat movements (the head
follows), at 37–80 beats a minute, with the Effort of one preset.  Read from
anything else (a squat, a walk, tai chi, a dance that travels) the nearest
preset is not an emotion of the mover, only the least unlike of four
numbers, so :func:`emotion_domain` checks that a phrase is a port de bras of
this kind before any emotion is read, and says which check failed.

Each check is a :class:`DomainCheck`: a measured value, the range the
presets' performances occupy, and whether the value lies inside.  Checks on
the joints are in body heights (so a child and an adult are alike) and use
5–95 % percentile ranges (so capture jitter and a lost frame do not decide).
A check that cannot be measured (no pelvis, ankles out of the picture)
fails: an emotion is read only from a phrase known to be a port de bras.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..notation.model import Score

__all__ = [
    "ANKLE_RANGE_MAX",
    "ARM_SHARE_MIN",
    "EFFORT_DISTANCE_MAX",
    "LEG_SHARE_MAX",
    "MIN_ARM_MOVEMENTS",
    "MOVEMENT_BEATS",
    "PELVIS_RISE_MAX",
    "PELVIS_TRAVEL_MAX",
    "TEMPO_RANGE",
    "DomainCheck",
    "EmotionDomain",
    "emotion_domain",
]

#: Tempo (beats per minute) of the presets' performances: the presets' own
#: 37–80 bpm (:data:`PRESETS`) widened by two performer standard deviations
#: of tempo (×/÷ 1.22, ``emotion.PERFORMER_SD``): 30–100 bpm.
TEMPO_RANGE = (30.0, 100.0)
#: Median length of the phrase's movements, beats.  The port de bras moves
#: the arms one count at a time; the estimator's working range is ½–4 beats.
MOVEMENT_BEATS = (0.5, 4.0)
#: Fewest measured arm movements: one movement is a gesture, not a phrase,
#: and its Effort (two numbers from one curve) is too uncertain to tell
#: the presets apart.
MIN_ARM_MOVEMENTS = 2
#: Smallest share of the measured movements made by the arms (whole arms or
#: their segments): the port de bras is arm-led; the head may follow.
ARM_SHARE_MIN = 0.5
#: Largest share of leg gestures (a port de bras stands on both feet).
LEG_SHARE_MAX = 0.1
#: Largest 5–95 % range of the pelvis height, body heights: 6 % (10 cm for
#: 1.70 m) allows a breath and a rise of the chest, not a plié or a squat
#: (a squat drops the pelvis by a quarter of the height).
PELVIS_RISE_MAX = 0.06
#: Largest 5–95 % horizontal range of the pelvis, body heights: 8 % (14 cm)
#: allows a sway over the feet, not a step, a weight transfer of tai chi
#: (a stance apart: ~0.2 heights) or a walk.
PELVIS_TRAVEL_MAX = 0.08
#: Largest 5–95 % range of either ankle's position, body heights: the feet
#: stay on the floor where they are (5 %, beyond the capture's ankle jitter).
ANKLE_RANGE_MAX = 0.05
#: Largest Mahalanobis distance of the phrase's (time, weight, space, ln
#: tempo) from the nearest preset, in the spread of the presets'
#: performances plus this phrase's posterior uncertainty: the 99 % point of
#: χ² with 4 degrees of freedom is 13.28, so 1 performance of a preset in
#: 100 would be refused (√13.28 = 3.64).
EFFORT_DISTANCE_MAX = 3.64

_ARM_PARTS = frozenset({"right_arm", "left_arm", "right_upper_arm", "left_upper_arm", "right_forearm", "left_forearm"})
_LEG_PARTS = frozenset({"right_leg", "left_leg", "right_thigh", "left_thigh", "right_shin", "left_shin"})


@dataclass(frozen=True)
class DomainCheck:
    """One test of the port-de-bras domain.

    Attributes
    ----------
    name : str
        Short identifier (``tempo``, ``pelvis_rise`` …).
    value : float
        The phrase's measured value (NaN when it could not be measured).
    low, high : float
        The range the presets' performances occupy (inclusive).
    unit : str
    ok : bool
        `value` is finite and inside [low, high].
    reason : str
        Why the check failed, in words for the page ("" when it passed).
    """

    name: str
    value: float
    low: float
    high: float
    unit: str
    ok: bool
    reason: str = ""

    def to_dict(self) -> dict:
        """JSON-ready form (NaN written as None)."""
        v = float(self.value)
        return {
            "name": self.name,
            "value": v if np.isfinite(v) else None,
            "range": [self.low, self.high],
            "unit": self.unit,
            "ok": self.ok,
            "reason": self.reason,
        }


@dataclass(frozen=True)
class EmotionDomain:
    """Whether a phrase lies within what the emotion presets describe.

    Attributes
    ----------
    checks : tuple of DomainCheck
    """

    checks: tuple

    @property
    def inside(self) -> bool:
        """Every check passed: the emotion may be read."""
        return all(c.ok for c in self.checks)

    @property
    def reasons(self) -> tuple:
        """The failed checks' reasons, in check order."""
        return tuple(c.reason for c in self.checks if not c.ok)

    def to_dict(self) -> dict:
        """JSON-ready form: ``{"inside", "reasons", "checks"}``."""
        return {"inside": self.inside, "reasons": list(self.reasons), "checks": [c.to_dict() for c in self.checks]}


def _check(name: str, value: float, low: float, high: float, unit: str, what: str) -> DomainCheck:
    """A range check; `what` phrases the failure (``{v}`` the value, ``{lo}``/``{hi}`` the range)."""
    v = float(value)
    ok = bool(np.isfinite(v) and low <= v <= high)
    reason = ""
    if not ok:
        vs = "not measured" if not np.isfinite(v) else f"{v:.3g} {unit}".strip()
        if not np.isfinite(high):
            span = f"at least {low:g}"
        elif low == 0:
            span = f"at most {high:g}"
        else:
            span = f"{low:g}–{high:g}"
        reason = f"{what}: {vs}, a port de bras {span} {unit}".rstrip()
    return DomainCheck(name, v, float(low), float(high), unit, ok, reason)


def _spread(x: np.ndarray) -> float:
    """5–95 % percentile range of the finite entries of `x` (NaN when too few)."""
    x = x[np.isfinite(x)]
    if x.size < 3:
        return float("nan")
    lo, hi = np.percentile(x, [5, 95])
    return float(hi - lo)


def _body_height(joints: np.ndarray) -> float:
    """The performer's standing extent, metres: 95th percentile over frames of the joints' vertical span."""
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # frames with no joint: NaN, dropped below
        span = np.nanmax(joints[:, :, 2], axis=1) - np.nanmin(joints[:, :, 2], axis=1)
    span = span[np.isfinite(span)]
    return float(np.percentile(span, 95)) if span.size else float("nan")


def _joint(joints: np.ndarray, confidence, names, name: str) -> np.ndarray:
    """(T, 3) positions of `name` with NaN where missing or of zero confidence."""
    if name not in names:
        return np.full((joints.shape[0], 3), np.nan)
    j = list(names).index(name)
    p = joints[:, j, :].copy()
    if confidence is not None:
        p[~(np.asarray(confidence)[:, j] > 0)] = np.nan
    return p


def body_checks(joints, confidence, joint_names) -> tuple:
    """Checks on the joints: the pelvis stays at its height and place, the feet on theirs.

    Parameters
    ----------
    joints : (T, J, 3) ndarray
        World positions, metres, z up.
    confidence : (T, J) ndarray or None
    joint_names : sequence of str

    Returns
    -------
    tuple of DomainCheck
    """
    joints = np.asarray(joints, dtype=float)
    height = _body_height(joints)
    if not (np.isfinite(height) and height > 0):
        height = float("nan")
    pelvis = _joint(joints, confidence, joint_names, "pelvis")
    rise = _spread(pelvis[:, 2]) / height
    travel = float(np.hypot(_spread(pelvis[:, 0]), _spread(pelvis[:, 1]))) / height
    ankles = [_joint(joints, confidence, joint_names, f"{side}_ankle") for side in ("right", "left")]
    ankle = max((float(np.sqrt(sum(_spread(a[:, k]) ** 2 for k in range(3)))) for a in ankles), default=np.nan)
    return (
        _check("pelvis_rise", rise, 0.0, PELVIS_RISE_MAX, "heights", "the pelvis rises and sinks (a plié, a squat)"),
        _check("pelvis_travel", travel, 0.0, PELVIS_TRAVEL_MAX, "heights", "the pelvis travels (steps or a walk)"),
        _check("feet", ankle / height, 0.0, ANKLE_RANGE_MAX, "heights", "the feet move"),
    )


def score_checks(score: Score, measured_parts) -> tuple:
    """Checks on the phrase: tempo, movement length, which parts move.

    Parameters
    ----------
    score : Score
    measured_parts : sequence of str
        The part of each movement whose Effort was measured.
    """
    gestures = [s for s in score.symbols if s.part in _ARM_PARTS | _LEG_PARTS or s.part in ("head", "chest")]
    beats = float(np.median([float(s.duration) for s in gestures])) if gestures else float("nan")
    parts = list(measured_parts)
    n_arm = sum(p in _ARM_PARTS for p in parts)
    share = n_arm / len(parts) if parts else float("nan")
    legs = sum(s.part in _LEG_PARTS for s in gestures) / len(gestures) if gestures else float("nan")
    return (
        _check("tempo", float(score.tempo), TEMPO_RANGE[0], TEMPO_RANGE[1], "bpm", "tempo outside the presets'"),
        _check("movement_beats", beats, *MOVEMENT_BEATS, "beats", "movements of another length"),
        _check("arm_movements", n_arm, MIN_ARM_MOVEMENTS, np.inf, "", "too few arm movements measured"),
        _check("arm_share", share, ARM_SHARE_MIN, 1.0, "", "not led by the arms"),
        _check("leg_share", legs, 0.0, LEG_SHARE_MAX, "", "the legs gesture"),
    )


def effort_check(x, sd, spread) -> DomainCheck:
    """Distance of the phrase's features from the nearest preset (see :data:`EFFORT_DISTANCE_MAX`).

    Parameters
    ----------
    x, sd : (4,) array_like
        Features (time, weight, space, ln tempo) and their posterior sd.
    spread : (4,) array_like
        Spread of the presets' performances about the presets.
    """
    from .emotion import preset_features

    _, mu = preset_features()
    var = np.asarray(spread, float) ** 2 + np.nan_to_num(np.asarray(sd, float), nan=0.0) ** 2
    d = float(np.sqrt(np.min(np.sum((np.asarray(x, float) - mu) ** 2 / var, axis=1))))
    return _check("effort_distance", d, 0.0, EFFORT_DISTANCE_MAX, "sd", "Effort unlike every preset")


def emotion_domain(score, measured_parts, joints, confidence, joint_names, x=None, sd=None, spread=None):
    """All checks of the port-de-bras domain for one phrase.

    Parameters
    ----------
    score : Score
    measured_parts : sequence of str
        Part of each measured movement.
    joints, confidence, joint_names
        As for :func:`body_checks`.
    x, sd, spread : (4,) array_like, optional
        Features for :func:`effort_check` (skipped, and failed, when `x` is None:
        no pooled Effort).

    Returns
    -------
    EmotionDomain
    """
    checks = list(score_checks(score, measured_parts)) + list(body_checks(joints, confidence, joint_names))
    if x is None:
        checks.append(_check("effort_distance", np.nan, 0.0, EFFORT_DISTANCE_MAX, "sd", "no pooled Effort"))
    else:
        checks.append(effort_check(x, sd, spread))
    return EmotionDomain(tuple(checks))
