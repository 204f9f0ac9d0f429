"""Laban Effort: the logistic model, emotion presets, and its estimation."""

from .model import TIME_RANGE, WEIGHT_RANGE, progress, progress_speed, space_radius
from .presets import PRESETS, Preset

__all__ = ["PRESETS", "Preset", "TIME_RANGE", "WEIGHT_RANGE", "progress", "progress_speed", "space_radius"]
