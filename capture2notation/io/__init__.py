"""Input and output: video, motion files (BVH, Kinect CSV), truth sidecars.

The readers most callers need are re-exported here; the format modules
(:mod:`.bvh`, :mod:`.kinect`, :mod:`.truth`, :mod:`.video`) hold the rest.
A motion file as fitted joints of our skeleton is
:func:`capture2notation.fitting.read_motion` (it retargets with the fitter).
"""

from .truth import Truth, read_truth, write_truth
from .video import iter_frames, probe

__all__ = ["Truth", "iter_frames", "probe", "read_truth", "write_truth"]
