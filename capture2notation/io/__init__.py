"""Input and output: atomic writes, video, motion files (BVH, Kinect CSV, truth sidecars).

The readers most callers need are re-exported here; the format modules
(:mod:`.bvh`, :mod:`.kinect`, :mod:`.truth`, :mod:`.video`) hold the rest.
"""

from .atomic import atomic_path, write_bytes, write_text
from .motion import MotionData, read_motion
from .truth import Truth, read_truth, write_truth
from .video import iter_frames, probe

__all__ = ["MotionData", "Truth", "atomic_path", "iter_frames", "probe", "read_motion", "read_truth",
           "write_bytes", "write_text", "write_truth"]
