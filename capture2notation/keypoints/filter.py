"""Temporal smoothing of landmarks: MediaPipe's one-euro filter, vectorised.

Port of ``mediapipe/util/filtering/one_euro_filter.cc`` as used by
``LandmarksSmoothingCalculator``: every coordinate of every landmark has its
own filter, but all of them advance together, so one :class:`OneEuroFilter`
holds arrays of any shape.  The velocity is measured in units of the object
size (``value_scale = 1 / object_scale``, the mean of the landmarks'
bounding-box width and height), so the same parameters suit a person filling
the frame and a small one.  Parameters used by MediaPipe's pose graph
(``pose_landmark_filtering.pbtxt``) are in :data:`POSE_FILTER`,
:data:`AUX_FILTER` and :data:`WORLD_FILTER`; visibilities get an exponential
low-pass with ``alpha = 0.1`` (:class:`LowPass`).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "AUX_FILTER",
    "POSE_FILTER",
    "VISIBILITY_ALPHA",
    "WORLD_FILTER",
    "LowPass",
    "OneEuroFilter",
    "object_scale",
]

#: (min_cutoff Hz, beta, derivative cutoff Hz) for the 33 image landmarks.
POSE_FILTER = (0.1, 40.0, 1.0)
#: Heavier smoothing for the two auxiliary points that place the next crop.
AUX_FILTER = (0.01, 1.0, 1.0)
#: World landmarks (MediaPipe filters them without value scaling).
WORLD_FILTER = (0.1, 40.0, 1.0)
VISIBILITY_ALPHA = 0.1


def object_scale(xy: np.ndarray) -> float:
    """Mean of the bounding-box width and height of points ``xy (K, >=2)``, ignoring NaN."""
    pts = xy[..., :2]
    pts = pts[np.isfinite(pts).all(axis=-1)]
    if pts.shape[0] == 0:
        return float("nan")
    span = pts.max(axis=0) - pts.min(axis=0)
    return float(span.mean())


def _alpha(cutoff, dt):
    tau = 1.0 / (2.0 * np.pi * cutoff)
    return 1.0 / (1.0 + tau / dt)


class OneEuroFilter:
    """One-euro filter over an array of independent signals.

    Parameters
    ----------
    min_cutoff : float
        Cutoff frequency (Hz) when the signal is still: lower = smoother.
    beta : float
        How fast the cutoff rises with speed: higher = less lag when moving.
    derivative_cutoff : float
        Cutoff frequency (Hz) of the speed estimate.
    frequency : float
        Sampling rate assumed before two timestamps have been seen (Hz).

    Notes
    -----
    A NaN input (a missing landmark) gives a NaN output and resets that
    signal, as MediaPipe resets its filters when the pose is lost; the next
    valid value starts it afresh.  Non-increasing timestamps return the input
    unchanged (MediaPipe does the same).
    """

    def __init__(self, min_cutoff: float, beta: float, derivative_cutoff: float = 1.0, frequency: float = 30.0):
        if min_cutoff <= 0 or derivative_cutoff <= 0 or frequency <= 0:
            raise ValueError(
                f"one-euro cutoffs and frequency must be > 0, got min_cutoff={min_cutoff}, "
                f"derivative_cutoff={derivative_cutoff}, frequency={frequency}"
            )
        self.min_cutoff = float(min_cutoff)
        self.beta = float(beta)
        self.derivative_cutoff = float(derivative_cutoff)
        self.frequency = float(frequency)
        self.reset()

    def reset(self) -> None:
        """Forget all state."""
        self._last_time = None
        self._raw = None  # last raw value per signal (NaN = no history)
        self._x = None  # last filtered value
        self._dx = None  # last filtered derivative

    def __call__(self, t: float, value, value_scale: float = 1.0) -> np.ndarray:
        """Filter one sample.

        Parameters
        ----------
        t : float
            Timestamp, seconds.
        value : ndarray
            Signals of any fixed shape.
        value_scale : float
            Multiplies the raw speed (1 / object size for landmarks).

        Returns
        -------
        ndarray
            Filtered signals, same shape as `value`.
        """
        value = np.asarray(value, dtype=float)
        if self._raw is None or self._raw.shape != value.shape:
            self._raw = np.full(value.shape, np.nan)
            self._x = np.full(value.shape, np.nan)
            self._dx = np.zeros(value.shape)
        if self._last_time is not None:
            if t <= self._last_time:
                return value.copy()
            self.frequency = 1.0 / (t - self._last_time)
        self._last_time = t
        dt = 1.0 / self.frequency
        have = np.isfinite(self._raw)
        dvalue = np.where(have, (value - self._raw) * value_scale * self.frequency, 0.0)
        a_d = _alpha(self.derivative_cutoff, dt)
        # The derivative low-pass starts from its first sample.
        dx = np.where(have & np.isfinite(self._dx), a_d * dvalue + (1 - a_d) * self._dx, dvalue)
        cutoff = self.min_cutoff + self.beta * np.abs(dx)
        a = _alpha(cutoff, dt)
        x = np.where(have, a * value + (1 - a) * self._x, value)
        missing = ~np.isfinite(value)
        self._raw = np.where(missing, np.nan, value)
        self._x = np.where(missing, np.nan, x)
        self._dx = np.where(missing, 0.0, dx)
        return np.where(missing, np.nan, x)


class LowPass:
    """Exponential smoothing ``y = alpha * x + (1 - alpha) * y_prev`` over arrays (NaN resets)."""

    def __init__(self, alpha: float = VISIBILITY_ALPHA):
        if not 0 < alpha <= 1:
            raise ValueError(f"low-pass alpha must be in (0, 1], got {alpha}")
        self.alpha = float(alpha)
        self._y = None

    def reset(self) -> None:
        """Forget all state."""
        self._y = None

    def __call__(self, value) -> np.ndarray:
        """Filter one sample of signals of any fixed shape."""
        value = np.asarray(value, dtype=float)
        if self._y is None or self._y.shape != value.shape:
            self._y = np.full(value.shape, np.nan)
        y = np.where(np.isfinite(self._y), self.alpha * value + (1 - self.alpha) * self._y, value)
        self._y = y
        return y.copy()
