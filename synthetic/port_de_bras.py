"""Random port-de-bras-like phrases: the kind of phrase the emotion presets describe.

Neagle's presets were measured on a port de bras: the dancer stands on both
feet and the arms lead one-count movements between the classical positions,
the head following now and then.  :func:`random_port_de_bras` draws such
phrases (a held support, both arms moving together, symmetric or not, an
occasional head movement) so emotion readings can be calibrated and tested
on performances of the presets' own kind, seed by seed.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from capture2notation.notation.directions import canonical_vector
from capture2notation.notation.model import Effort, Score, Symbol

__all__ = ["ARM_POSITIONS", "random_port_de_bras"]

#: (direction, level, bend) of the right arm in the port de bras' positions
#: (en bas, en avant, en haut, à la seconde and between); the left arm takes
#: their mirror images.  Rounded arms are bend 1.
ARM_POSITIONS = (
    ("place", "low", 1),
    ("forward", "low", 1),
    ("forward", "middle", 1),
    ("place", "high", 1),
    ("forward", "high", 1),
    ("right", "middle", 1),
    ("right", "middle", 0),
    ("right_forward", "middle", 0),
    ("right", "high", 0),
    ("right", "low", 0),
)
#: Head directions (level high = the face level) it may turn to.
_HEAD = (("right_forward", "high"), ("left_forward", "high"), ("place", "high"))
#: Smallest angle between successive arm positions, degrees: a smaller
#: swing barely moves the wrist, and Effort needs a movement to read.
_MIN_SWING_DEG = 30.0


def _mirror(direction: str) -> str:
    return direction.replace("right", "@").replace("left", "right").replace("@", "left")


def _next_position(rng: np.random.Generator, prev) -> tuple:
    u = canonical_vector(prev[0], prev[1])
    cos_min = np.cos(np.radians(_MIN_SWING_DEG))
    choices = [p for p in ARM_POSITIONS if float(np.dot(u, canonical_vector(p[0], p[1]))) < cos_min]
    return choices[int(rng.integers(len(choices)))]


def random_port_de_bras(
    rng: np.random.Generator,
    n_moves: int = 4,
    tempo=60,
    effort: Effort | None = None,
    beats=(Fraction(1),),
    symmetric: float = 0.6,
    head: float = 0.3,
) -> Score:
    """A random port de bras of `n_moves` arm movements on a held support.

    Parameters
    ----------
    rng : numpy.random.Generator
        The only source of randomness.
    n_moves : int
        Arm movements (both arms move in each, >= 1).
    tempo : int or Fraction
        Beats per minute.
    effort : Effort, optional
        Written into the score's header (the dancer performs with it).
    beats : sequence of Fraction
        Movement lengths drawn from, beats.
    symmetric : float
        Probability that the left arm mirrors the right (else it takes its
        own position).
    head : float
        Probability that the head turns during a movement.

    Returns
    -------
    Score
    """
    rng = np.random.default_rng(rng)
    right = left = ARM_POSITIONS[0]
    syms, beat = [], Fraction(0)
    for _ in range(max(1, int(n_moves))):
        dur = Fraction(beats[int(rng.integers(len(beats)))])
        right = _next_position(rng, right)
        left = right if rng.random() < symmetric else _next_position(rng, left)
        syms.append(Symbol(beat, dur, "right_arm", right[0], right[1], bend=right[2]))
        syms.append(Symbol(beat, dur, "left_arm", _mirror(left[0]), left[1], bend=left[2]))
        if rng.random() < head:
            h = _HEAD[int(rng.integers(len(_HEAD)))]
            syms.append(Symbol(beat, dur, "head", h[0], h[1]))
        beat += dur
    support = Symbol(Fraction(0), beat, "support", "place", "middle")
    return Score(symbols=(support, *syms), tempo=Fraction(tempo), effort=effort, title="random port de bras")
