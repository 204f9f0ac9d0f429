"""Emotion probabilities against the presets."""

import numpy as np
import pytest

from capture2notation.effort.emotion import (
    SPREAD,
    emotion_probabilities,
    features,
    preset_features,
    same_or_different,
)
from capture2notation.errors import EffortError
from capture2notation.notation.effort import PRESETS


@pytest.mark.parametrize("emotion", list(PRESETS))
def test_each_preset_is_its_own_most_probable_emotion(emotion):
    p = PRESETS[emotion]
    probs = emotion_probabilities(features(p.effort.time, p.effort.weight, p.effort.space, float(p.tempo)))
    assert set(probs) == {"happy", "sad", "angry", "afraid"}
    assert sum(probs.values()) == pytest.approx(1.0, abs=1e-12)
    assert max(probs, key=probs.get) == emotion


def test_uncertainty_spreads_the_probabilities():
    names, mu = preset_features()
    x = 0.5 * (mu[names.index("sad")] + mu[names.index("afraid")]) + np.array([0, 0, 0.1, 0.03])
    sharp = emotion_probabilities(x)
    vague = emotion_probabilities(x, sd=[1.0, 0.2, 1.0, 0.5])
    entropy = [-sum(v * np.log(v) for v in p.values() if v > 0) for p in (sharp, vague)]
    assert entropy[1] > entropy[0]
    # happy and angry share a tempo: halfway between them, tempo says nothing
    mid = 0.5 * (mu[names.index("happy")] + mu[names.index("angry")])
    p = emotion_probabilities(mid, temperature=1.0)
    assert p["happy"] + p["angry"] > 0.99
    # the calibrated temperature softens the claim but keeps the two equal and ahead
    q = emotion_probabilities(mid)
    assert q["happy"] == pytest.approx(q["angry"], rel=1e-9) and min(q["happy"], q["angry"]) > max(
        q["sad"], q["afraid"]
    )


def test_same_or_different_and_bad_features():
    a = {"happy": 0.7, "sad": 0.1, "angry": 0.1, "afraid": 0.1}
    b = {"happy": 0.2, "sad": 0.1, "angry": 0.6, "afraid": 0.1}
    assert same_or_different(a, a) and not same_or_different(a, b)
    with pytest.raises(EffortError, match="tempo"):
        features(-2.4, 0.6, 0.0, 0.0)
    with pytest.raises(EffortError, match="4 finite"):
        emotion_probabilities([np.nan, 0.5, 0.5, 4.0])
    assert len(SPREAD) == 4 and all(v > 0 for v in SPREAD)


def test_temperature_flattens_and_keeps_the_order():
    from capture2notation.effort.emotion import emotion_log_likelihoods

    names, mu = preset_features()
    x = 0.5 * (mu[names.index("sad")] + mu[names.index("afraid")]) + np.array([0.05, 0.0, 0.2, 0.0])
    ll = emotion_log_likelihoods(x)
    sharp, flat = emotion_probabilities(x, temperature=0.5), emotion_probabilities(x, temperature=4.0)
    assert max(sharp, key=sharp.get) == max(flat, key=flat.get) == names[int(np.argmax(ll))]
    assert max(flat.values()) < max(sharp.values())
    # temperature 1 is the plain Gaussian posterior over equal priors
    p = np.exp(ll - ll.max())
    assert emotion_probabilities(x, temperature=1.0)["sad"] == pytest.approx(p[names.index("sad")] / p.sum())
