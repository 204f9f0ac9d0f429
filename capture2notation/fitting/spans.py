"""A long clip fitted in overlapping spans: memory bounded, the same joints.

The fit's working arrays (targets, data terms, the arm-depth candidates,
the exact smoothing's band) grow by about 30 kB a frame: 180 MB for four
minutes at 25 fps, 2.7 GB for an hour.  A clip longer than
:data:`SPAN_S` is therefore fitted span by span, each span with
:data:`CONTEXT_S` of the clip on both sides as context, and only the span's
own frames kept.  What belongs to the whole clip is decided once, before
the spans: the camera (focal length from frames spread over the clip) and
the figure's proportions (:data:`PROPORTION_FRAMES` frames spread over it).

The temporal priors couple a frame to its neighbours through second
differences whose influence decays within a few frames at the default
weights, so two seconds of context leave a span's kept frames as the
whole-clip fit has them; what can still differ are the few per-span
statistics of the arm-depth choice (its rest offset of a hanging arm).
``benchmarks/bench_scale.py --spans`` compares both ways on the held-out
phrases.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..errors import FittingError
from .result import FitResult

__all__ = ["CONTEXT_S", "PROPORTION_FRAMES", "SPAN_S", "spread_frames", "stitch", "track_spans"]

#: Seconds of a clip fitted at once (about 45 MB of working memory at 25 fps).
SPAN_S = 60.0
#: Seconds of context fitted on each side of a span and then dropped.
CONTEXT_S = 2.0
#: Most frames measuring the figure's proportions: three minutes at 25 fps.
#: Its medians and percentiles over a longer clip's evenly spread frames
#: are those of the whole clip to within their sampling error (a few mm).
PROPORTION_FRAMES = 4500


def track_spans(n_frames: int, fps: float, span_s: float = SPAN_S, context_s: float = CONTEXT_S) -> list:
    """Spans of a clip of `n_frames` frames.

    Parameters
    ----------
    n_frames : int
    fps : float
        Frames per second.
    span_s, context_s : float
        Seconds per span (``inf``: one span), and of context on each side (>= 0).

    Returns
    -------
    list of (start, stop, keep_start, keep_stop)
        Frame indices: fit ``[start, stop)``, keep ``[keep_start, keep_stop)``.
        The kept ranges tile ``[0, n_frames)``; one span when the clip is no
        longer than a span with its context.

    Raises
    ------
    FittingError
        On a non-positive span or frame rate, or negative context.
    """
    if not (np.isfinite(fps) and fps > 0):
        raise FittingError(f"fps must be a positive number, got {fps!r}")
    if not span_s > 0:  # NaN too; inf: never split
        raise FittingError(f"span_s must be > 0 seconds, got {span_s!r}")
    if not (np.isfinite(context_s) and context_s >= 0):
        raise FittingError(f"context_s must be >= 0 seconds, got {context_s!r}")
    n = int(n_frames)
    context = int(round(context_s * fps))
    if np.isinf(span_s) or n <= span_s * fps + 2 * context:
        return [(0, n, 0, n)]
    span = max(1, int(round(span_s * fps)))
    n_spans = -(-n // span)
    edges = np.linspace(0, n, n_spans + 1).round().astype(int)
    return [(max(a - context, 0), min(b + context, n), int(a), int(b)) for a, b in itertools.pairwise(edges.tolist())]


def spread_frames(n_frames: int, most: int) -> np.ndarray:
    """Indices of at most `most` frames spread evenly over `n_frames` (all of them when fewer)."""
    if n_frames <= most:
        return np.arange(n_frames)
    return np.unique(np.linspace(0, n_frames - 1, most).round().astype(int))


def stitch(parts, spans) -> FitResult:
    """One :class:`FitResult` from the spans' results, keeping each span's own frames.

    Parameters
    ----------
    parts : sequence of FitResult
        The fit of each span's ``[start, stop)``.
    spans : sequence of (start, stop, keep_start, keep_stop)
        As returned by :func:`track_spans`.
    """
    if len(parts) != len(spans) or not parts:
        raise FittingError(f"stitch needs one result per span, got {len(parts)} for {len(spans)} spans")
    if len(parts) == 1:
        return parts[0]
    cuts = [slice(k0 - a, k1 - a) for a, _b, k0, k1 in spans]

    def joined(name):
        return np.concatenate([np.asarray(getattr(p, name))[c] for p, c in zip(parts, cuts)])

    return parts[0].replace(
        times=joined("times"),
        joints=joined("joints"),
        angles=joined("angles"),
        root=joined("root"),
        confidence=joined("confidence"),
    )
