"""Random port-de-bras phrases: a held support, both arms in every movement, real swings."""

import numpy as np

from capture2notation.notation.directions import canonical_vector
from synthetic.port_de_bras import random_port_de_bras


def test_phrase_shape_and_swings():
    for seed in range(20):
        s = random_port_de_bras(np.random.default_rng(seed), 5, tempo=64)
        (support,) = [x for x in s.symbols if x.part == "support"]
        arms = [x for x in s.symbols if x.part.endswith("arm")]
        assert support.start == 0 and support.end == max(x.end for x in s.symbols)
        assert len(arms) == 10 and {x.part for x in arms} == {"right_arm", "left_arm"}
        right = [x for x in arms if x.part == "right_arm"]
        prev = canonical_vector("place", "low")
        for x in right:
            u = canonical_vector(x.direction, x.level)
            assert np.degrees(np.arccos(np.clip(prev @ u, -1, 1))) > 29.9
            prev = u
