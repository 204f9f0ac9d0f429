"""capture2notation: dance on video or motion capture → dance notation.

Subpackages, one per stage: :mod:`~capture2notation.body` (joint tree and
kinematics), :mod:`~capture2notation.notation` (scores and their files),
:mod:`~capture2notation.keypoints` (BlazePose / colour markers),
:mod:`~capture2notation.fitting` (2D → 3D joints), :mod:`~capture2notation.quantise`
(joints → symbols), :mod:`~capture2notation.effort` (Laban Effort),
:mod:`~capture2notation.compare` (metrics), :mod:`~capture2notation.io`
(video, BVH, Kinect, truth sidecars).
"""

from .errors import C2NError

__version__ = "0.1.0"
__all__ = ["C2NError", "__version__"]
