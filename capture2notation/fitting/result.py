"""The output of fitting: 3D joints, joint angles and confidences over time."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..body import JOINTS
from ..errors import FittingError

__all__ = ["FitResult", "labelled_confidence"]

#: Joints whose identity a left/right swap exchanges.
_SIDED = np.array([name.startswith(("left_", "right_")) for name in JOINTS])


@dataclass(frozen=True, eq=False)
class FitResult:
    """A fitted (or read) motion of the canonical skeleton.

    Attributes
    ----------
    fps : float
        Frames per second.
    times : (T,) ndarray
        Seconds.
    joints : (T, J, 3) ndarray
        World positions of :data:`~capture2notation.body.JOINTS`, metres, z
        up, floor z = 0 where it can be inferred; NaN in frames that could not
        be fitted.
    angles : (T, J, 3) ndarray
        Local Euler angles ``(rx, ry, rz)``, radians (ARCHITECTURE.md).
    root : (T, 3) ndarray
        Pelvis position, metres.
    confidence : (T, J) ndarray
        In [0, 1]; 0 where a joint is not measured.
    offsets : (J, 3) ndarray or None
        Per-clip offsets of each joint from its parent, metres:
        ``forward_kinematics`` with these offsets reproduces `joints` exactly
        (``Body(height)`` proportions reproduce them approximately).
    identity_confidence : (T,) ndarray or None
        One view's fit: the probability, per frame, that the keypoints'
        left and right were right (``KeypointTrack.identity_confidence``;
        NaN where not assessed); None where nothing decided them (motion
        files, several cameras).  `confidence` says how well each joint is
        measured; :meth:`labelled_confidence` also that it is the side it
        is called.
    front_readings : (T, 2) ndarray or None
        Where the front was decoded from one view's image
        (:func:`~capture2notation.fitting.yaw.with_image_yaw`): each frame's
        posterior probability of the front as decoded and of its mirror
        image, the reading the image cannot tell from it, turning the other
        way (:func:`~capture2notation.keypoints.yaw.yaw_decoding`;
        NaN where unknown); None otherwise.
    """

    fps: float
    times: np.ndarray
    joints: np.ndarray
    angles: np.ndarray
    root: np.ndarray
    confidence: np.ndarray
    offsets: np.ndarray | None = None
    front_readings: np.ndarray | None = None
    identity_confidence: np.ndarray | None = None

    def __post_init__(self):
        T = np.shape(self.times)[0] if np.ndim(self.times) == 1 else -1
        J = len(JOINTS)
        expect = {"joints": (T, J, 3), "angles": (T, J, 3), "root": (T, 3), "confidence": (T, J)}
        if self.front_readings is not None:
            expect["front_readings"] = (T, 2)
        if self.identity_confidence is not None:
            expect["identity_confidence"] = (T,)
        for name, shape in expect.items():
            if np.shape(getattr(self, name)) != shape:
                raise FittingError(
                    f"{type(self).__name__}.{name} must have shape {shape}, got {np.shape(getattr(self, name))}"
                )
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise FittingError(f"{type(self).__name__}.fps must be positive, got {self.fps!r}")

    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return int(self.times.shape[0])

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the J joints (:data:`~capture2notation.body.JOINTS`)."""
        return JOINTS

    def labelled_confidence(self) -> np.ndarray:
        """(T, J) `confidence` times :attr:`identity_confidence` on every left and right joint.

        What a symbol of a sided part rests on: the joint measured, and
        under its own label (NaN identity leaves a frame as it is).
        """
        if self.identity_confidence is None:
            return np.asarray(self.confidence, float)
        ident = np.asarray(self.identity_confidence, float)
        factor = np.where(np.isfinite(ident), np.clip(ident, 0.0, 1.0), 1.0)
        out = np.array(self.confidence, dtype=float)
        out[:, _SIDED] *= factor[:, None]
        return out

    def replace(self, **changes):
        """A copy with some fields replaced."""
        return dataclasses.replace(self, **changes)


def labelled_confidence(motion) -> np.ndarray | None:
    """(T, J) any motion's joint confidence under its own labels: :meth:`FitResult.labelled_confidence`.

    An object with only ``confidence`` (a fit window of a test, say) gives
    that; one without it, None.
    """
    if isinstance(motion, FitResult):
        return motion.labelled_confidence()
    return getattr(motion, "confidence", None)
