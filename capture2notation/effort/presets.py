"""Emotion presets (Neagle 2005, Tables 5.1, 5.3, 5.5; DESIGN.md).

Afraid's space is not given by Neagle; 0.5 is this project's assumption.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from types import MappingProxyType

from ..notation.model import Effort

__all__ = ["PRESETS", "Preset"]


@dataclass(frozen=True)
class Preset:
    """An emotion's Effort and tempo."""

    emotion: str
    effort: Effort
    tempo: Fraction


PRESETS: MappingProxyType = MappingProxyType(
    {
        "happy": Preset("happy", Effort(time=-2.42, weight=0.60, space=0.0), Fraction(80)),
        "sad": Preset("sad", Effort(time=-2.19, weight=0.52, space=0.0), Fraction(37)),
        "angry": Preset("angry", Effort(time=-3.51, weight=0.41, space=1.0), Fraction(79)),
        "afraid": Preset("afraid", Effort(time=-2.3, weight=0.52, space=0.5), Fraction(43)),
    }
)
