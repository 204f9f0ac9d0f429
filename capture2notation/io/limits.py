"""What a recorded dance can be: the bounds every reader checks.

A value outside these bounds is not a performance but a corrupt or
mislabelled file (a wrong unit, a wrong field, a bit flip), so readers
refuse it with a one-line error before allocating anything that depends on
it.  They are also what keeps memory bounded: no reader allocates more than
a fixed multiple of ``MAX_FRAMES`` frames, whatever a header declares.
"""

from __future__ import annotations

__all__ = [
    "MAX_ABS_ANGLE_DEG",
    "MAX_ABS_FILE_LENGTH",
    "MAX_DURATION_S",
    "MAX_FPS",
    "MAX_FRAMES",
    "MAX_IMAGE_SIDE",
    "MAX_JOINTS",
    "MAX_TRUTH_TEXT",
    "MIN_FPS",
    "check_duration",
]

#: Seconds (6 h).  A full-length ballet with its intervals lasts about 3 h;
#: a file that spans more is a wrong time unit or a corrupt timestamp.
MAX_DURATION_S = 6 * 3600.0

#: Hz.  Optical motion capture records at up to about 1 kHz (high-speed
#: video at a few kHz is not used for dance); a faster rate is a wrong
#: ``Frame Time`` or timestamp unit.
MAX_FPS = 1000.0

#: Hz (one frame per 10 s).  Slower than that a file is a set of poses, not
#: motion that can be segmented into movements.
MIN_FPS = 0.1

#: Frames.  (T, 21, 3) float64 joints are 0.5 GB at this count, and the
#: fitting and quantising stages hold a few such arrays; it is 9 h at 30 fps
#: or 17 min at 1 kHz.
MAX_FRAMES = 1_000_000

#: Joints and end sites of one skeleton.  A full-body rig with fingers and a
#: face has about 300.
MAX_JOINTS = 1000

#: File units (BVH offsets and position channels).  The smallest length unit
#: BVH files use is the millimetre, and 10⁵ mm is 100 m: no body segment or
#: stage position is larger.
MAX_ABS_FILE_LENGTH = 1e5

#: Degrees (BVH rotation channels).  Exporters that unwrap angles stay far
#: below (10⁵° is 278 turns); beyond it float64 keeps no sub-degree precision
#: worth reading.
MAX_ABS_ANGLE_DEG = 1e5

#: Pixels: the longest image side a video or camera may have (16K video is 15360).
MAX_IMAGE_SIDE = 16384

#: Characters of one text field of a truth sidecar (the score or Effort JSON);
#: 16 MB holds a score far longer than any dance.
MAX_TRUTH_TEXT = 16_000_000


def check_duration(frames: int, fps: float) -> str | None:
    """Why `frames` at `fps` is not a dance, or None when it can be one.

    Parameters
    ----------
    frames : int
    fps : float
        Hz.
    """
    if not MIN_FPS <= fps <= MAX_FPS:
        return f"frame rate {fps:.6g} Hz is outside {MIN_FPS:g}-{MAX_FPS:g} Hz"
    if frames > MAX_FRAMES:
        return f"{frames} frames is more than the {MAX_FRAMES} a reader accepts"
    if frames / fps > MAX_DURATION_S:
        return (
            f"{frames} frames at {fps:.6g} Hz last {frames / fps / 3600:.3g} h, longer than {MAX_DURATION_S / 3600:g} h"
        )
    return None
