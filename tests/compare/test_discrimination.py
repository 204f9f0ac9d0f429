"""Same/different emotion trials in the manner of Neagle's Experiments 1–2."""

from collections import Counter
from fractions import Fraction

import numpy as np
import pytest

from capture2notation.compare.discrimination import (
    THESIS,
    SameDifferentObserver,
    experiment1_trials,
    experiment2_trials,
    feature_vector,
    run_trials,
    summarise,
)
from capture2notation.effort import PRESETS
from capture2notation.errors import CompareError


def test_experiment1_design_counts():
    trials = experiment1_trials()
    assert len(trials) == 72
    per = Counter((t.complexity, t.pair) for t in trials)
    assert per[("easy", "sad-sad")] == 3 and per[("hard", "happy-angry")] == 2
    assert sum(t.same for t in trials) == sum(not t.same for t in trials) == 36
    assert len({t.pair for t in trials}) == 10


def test_experiment2_design_counts():
    trials = experiment2_trials()
    assert len(trials) == 96
    assert {t.frame_rate for t in trials} == {Fraction(5), Fraction(25, 3), Fraction(25, 2), Fraction(25)}
    assert {t.pair for t in trials} == {
        "happy-happy",
        "sad-sad",
        "angry-angry",
        "happy-sad",
        "happy-angry",
        "sad-angry",
    }
    assert THESIS["experiment1_overall"] == pytest.approx(78.70)


def performances(rng, n_takes, noise):
    """Takes of each preset with Gaussian jitter on the observer's features."""
    feats, emos = [], []
    for name, p in PRESETS.items():
        base = feature_vector(
            {"time": p.effort.time, "weight": p.effort.weight, "space": p.effort.space, "tempo": float(p.tempo)}
        )
        for _ in range(n_takes):
            feats.append(base + rng.normal(scale=noise, size=4))
            emos.append(name)
    return np.array(feats), np.array(emos)


def test_observer_separates_clean_presets_and_confuses_sad_afraid():
    rng = np.random.default_rng(0)
    x, e = performances(rng, 6, noise=np.array([0.05, 0.01, 0.05, 0.02]))
    obs = SameDifferentObserver.calibrate(x, e)
    test_x, test_e = performances(np.random.default_rng(1), 4, noise=np.array([0.05, 0.01, 0.05, 0.02]))
    pool = {}
    for em in PRESETS:
        pool[(em, "easy", Fraction(25))] = test_x[test_e == em]
    res = run_trials(experiment1_trials(complexities=("easy",)), pool, obs, np.random.default_rng(2))
    s = summarise(res)
    assert s["n"] == 24
    assert s["by_pair"]["happy-sad"] == 100.0 and s["by_pair"]["sad-angry"] == 100.0
    assert s["by_kind"]["same"] == 100.0
    # Sad and afraid differ only by 0.1 in time and 0.5 in space: still told apart
    # at this noise, but the distance is the smallest of the different pairs.
    d = {r["pair"]: r["distance"] for r in res if not r["same"]}
    assert d["sad-afraid"] < d["happy-sad"]


def test_observer_at_chance_when_features_carry_no_emotion():
    rng = np.random.default_rng(5)
    x = rng.normal(size=(40, 4))
    e = np.repeat(["happy", "sad", "angry", "afraid"], 10)
    obs = SameDifferentObserver.calibrate(x, e)
    pool = {(em, "easy", Fraction(25)): rng.normal(size=(30, 4)) for em in ["happy", "sad", "angry", "afraid"]}
    trials = experiment1_trials(complexities=("easy",), same_repeats=30, different_repeats=20)
    s = summarise(run_trials(trials, pool, obs, np.random.default_rng(6)))
    assert 35.0 <= s["overall"] <= 65.0


def test_same_seed_same_trials():
    rng = np.random.default_rng(0)
    x, e = performances(rng, 3, noise=0.3)
    obs = SameDifferentObserver.calibrate(x, e)
    pool = {(em, "easy", Fraction(25)): x[e == em] for em in PRESETS}
    t = experiment1_trials(complexities=("easy",))
    a = run_trials(t, pool, obs, np.random.default_rng(9))
    b = run_trials(t, pool, obs, np.random.default_rng(9))
    assert a == b


def test_missing_features_and_pool_errors():
    obs = SameDifferentObserver(np.ones(4), 1.0)
    nan = np.full(4, np.nan)
    assert not obs.judge(nan, nan)  # nothing measured: not vouched "same"
    assert np.isnan(feature_vector({"tempo": 0})[3])
    with pytest.raises(CompareError, match="no performances"):
        run_trials(experiment1_trials(complexities=("easy",)), {}, obs, np.random.default_rng(0))
    with pytest.raises(CompareError, match="at least two emotions"):
        SameDifferentObserver.calibrate(np.zeros((4, 4)), ["sad"] * 4)


def test_a_feature_no_performance_measured_keeps_unit_scale_without_a_warning():
    import warnings

    rng = np.random.default_rng(3)
    x, e = performances(rng, 3, noise=0.3)
    x = np.array(x, float)
    x[:, 1] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        obs = SameDifferentObserver.calibrate(x, e)
    assert obs.scale[1] == 1.0 and np.all(np.isfinite(obs.scale))
