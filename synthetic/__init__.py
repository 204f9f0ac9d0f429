"""The virtual dancer: notation → motion (→ rendered frames with ground truth).

* :mod:`synthetic.interpolate` — easing functions (Cachola's four and the
  Laban Effort logistic);
* :mod:`synthetic.motion` — :class:`Motion`, key framing and the motion
  algebra of Cachola (1986) ch. 4;
* :mod:`synthetic.interpret` — :func:`interpret` a :class:`Score` into a
  :class:`Motion`, from :mod:`synthetic.limbs` (arms and legs),
  :mod:`synthetic.trunk` (head and chest), :mod:`synthetic.supports` (feet
  and weight), :mod:`synthetic.extremes` (paths within the joint limits)
  and :mod:`synthetic.rotations`; :mod:`synthetic.reach` reports what the
  joint limits forbid (:class:`UnreachableWarning`);
* :mod:`synthetic.random_scores` — random valid, renderable scores;
* :mod:`synthetic.phrases` — built-in phrases (Figure 7, third port de bras,
  a leg phrase);
* :mod:`synthetic.render` — the renderer.
"""

from .interpolate import INTERPOLATIONS, easing, effort_easing
from .interpret import interpret, unreachable
from .motion import Keyframe, Motion, keyframed, synchronize
from .phrases import builtin_phrases
from .random_scores import random_score

__all__ = [
    "INTERPOLATIONS",
    "Keyframe",
    "Motion",
    "builtin_phrases",
    "easing",
    "effort_easing",
    "interpret",
    "keyframed",
    "random_score",
    "synchronize",
    "unreachable",
]
