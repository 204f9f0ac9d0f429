"""Notation: the object model, direction/level thresholds and score files.

``read(path)`` / ``write(score, path)`` are the one front door to every
registered score format (see :mod:`capture2notation.notation.formats`).
"""

from .directions import bend_degree, canonical_vector, classify
from .formats import read, register_format, write
from .formats.json_format import score_from_dict, score_to_dict
from .formats.laban_editor import write_laban_editor
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
from .staff import render_staff

__all__ = [
    "DIRECTIONS",
    "EMOTIONS",
    "GESTURE_PARTS",
    "LEVELS",
    "PARTS",
    "PART_MIDDLE_JOINT",
    "PART_SEGMENTS",
    "SUPPORT_PARTS",
    "Effort",
    "Score",
    "Symbol",
    "bend_degree",
    "canonical_vector",
    "classify",
    "read",
    "register_format",
    "render_staff",
    "score_from_dict",
    "score_to_dict",
    "write",
    "write_laban_editor",
]
