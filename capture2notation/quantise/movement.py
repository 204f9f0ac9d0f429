"""One detected movement of one part: what segmentation and supports both produce."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

__all__ = ["Movement"]


@dataclass(frozen=True)
class Movement:
    """One detected movement of one part, in frames and seconds.

    ``start_time`` / ``end_time`` are the estimated instants the movement
    begins and arrives (seconds); ``end_frame`` is the first frame at the
    arrival pose.  ``amount`` is a turn's full turns (None otherwise; its
    ``level`` is then ``""``).
    """

    part: str
    start_frame: int
    end_frame: int
    start_time: float
    end_time: float
    direction: str
    level: str
    bend: int = 0
    amount: Fraction | None = None
