"""Notation: the object model, direction/level thresholds and score files.

``read(path)`` / ``write(score, path)`` are the one front door to every
registered score format (see :mod:`capture2notation.notation.formats`).
"""

from .directions import bend_degree, canonical_vector, classify
from .model import (
    DIRECTIONS,
    EMOTIONS,
    GESTURE_PARTS,
    LEVELS,
    PART_MIDDLE_JOINT,
    PART_SEGMENTS,
    PARTS,
    SUPPORT_PARTS,
    Effort,
    Score,
    Symbol,
)

__all__ = [
    "DIRECTIONS",
    "EMOTIONS",
    "GESTURE_PARTS",
    "LEVELS",
    "PART_MIDDLE_JOINT",
    "PART_SEGMENTS",
    "PARTS",
    "SUPPORT_PARTS",
    "Effort",
    "Score",
    "Symbol",
    "bend_degree",
    "canonical_vector",
    "classify",
]
