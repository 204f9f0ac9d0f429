"""The study grid (phrases × emotions × takes × conditions) and the performances.

A *condition* is one recording set-up (frame rate and resampling method,
image size, view, compression, pixel noise).  A *performance* is one take of
a phrase danced with an emotion by the virtual dancer; takes differ by a
seeded, stated amount of natural variation (tempo, Effort, body height), so
two takes of one emotion are never identical, as with Neagle's two dancers.
A *job* is one performance recorded under one condition.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from fractions import Fraction

import numpy as np

from capture2notation.compare.resample import as_rate
from capture2notation.effort import PRESETS
from capture2notation.errors import PipelineError
from capture2notation.notation.model import Effort

from .config import StudyConfig

__all__ = [
    "VARIATION",
    "Condition",
    "Job",
    "Performance",
    "build_conditions",
    "build_jobs",
    "phrase_complexity",
    "stable_seed",
    "take_variation",
]

#: Take-to-take variation of a performance (standard deviations), our stated
#: assumption: tempo ±4 % (log-normal), Effort time ±0.12, weight ±0.03,
#: space ±0.08; body height uniform in [1.60, 1.80] m.
VARIATION = {"log_tempo": 0.04, "time": 0.12, "weight": 0.03, "space": 0.08, "height": (1.60, 1.80)}


@dataclass(frozen=True)
class Condition:
    """One recording set-up.

    Attributes
    ----------
    factor : str
        The factor this condition varies from the baseline (``baseline``,
        ``frame_rate``, ``image_size``, ``view``, ``cameras``, ``compression``,
        ``noise``).
    frame_rate : str
        Exact rate as a fraction string (``"25/3"``).
    resampling : str
        ``keyframe`` or ``naive`` (``keyframe`` at the full rate, where the
        two coincide).
    width, height : int
    view : str
        The camera's view, or several calibrated cameras' joined by ``+``.
    compression : int
        JPEG quality, 0 = none.
    noise : float
        Pixel noise sigma.
    """

    factor: str
    frame_rate: str
    resampling: str
    width: int
    height: int
    view: str
    compression: int
    noise: float

    @property
    def rate(self) -> Fraction:
        return Fraction(self.frame_rate)

    def params(self) -> tuple:
        """Everything but the factor label: equal params = same recording."""
        return (self.frame_rate, self.resampling, self.width, self.height, self.view, self.compression, self.noise)

    @property
    def views(self) -> tuple[str, ...]:
        """The views of the condition's cameras (one unless :attr:`view` joins several with ``+``)."""
        return tuple(self.view.split("+"))

    @property
    def label(self) -> str:
        r = float(self.rate)
        return (
            f"{r:.4g} Hz {self.resampling}, {self.width}x{self.height}, {self.view}, "
            f"q={self.compression or 'none'}, noise={self.noise:g}"
        )


@dataclass(frozen=True)
class Performance:
    """One take of a phrase with an emotion (``split`` = ``test`` or ``train``)."""

    phrase: str
    complexity: str
    emotion: str
    take: int
    split: str


@dataclass(frozen=True)
class Job:
    """One performance recorded under one condition."""

    condition: Condition
    performance: Performance

    def key(self, cfg: StudyConfig, capture: str) -> dict:
        """Everything that determines this job's result."""
        return {
            "condition": asdict(self.condition) | {"factor": None},
            "performance": asdict(self.performance),
            "seed": cfg.seed,
            "capture": capture,
            "source_fps": cfg.source_fps,
            "bootstrap": cfg.bootstrap,
        }

    def digest(self, cfg: StudyConfig, capture: str, version: str) -> str:
        """Hash of the job's configuration (and the code version): the cache key."""
        text = json.dumps(self.key(cfg, capture) | {"version": version}, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:20]


def stable_seed(*parts) -> list[int]:
    """Seed sequence entropy from strings/ints, independent of Python's hash salt."""
    h = hashlib.sha256("\x1f".join(str(p) for p in parts).encode()).digest()
    return [int.from_bytes(h[i : i + 4], "little") for i in range(0, 16, 4)]


def _rate_str(r, source) -> str:
    f = as_rate(r, source)
    return f"{f.numerator}/{f.denominator}" if f.denominator != 1 else str(f.numerator)


def build_conditions(cfg: StudyConfig) -> list[Condition]:
    """Baseline plus one-factor-at-a-time variations, without duplicates.

    At the full source rate both resampling methods keep every frame; the
    condition is then written ``keyframe`` and shared.
    """
    b = cfg.baseline
    src = cfg.source_fps

    def make(factor, rate=None, method="keyframe", size=None, view=None, comp=None, noise=None):
        rate = b["frame_rate"] if rate is None else rate
        rs = _rate_str(rate, src)
        if as_rate(rate, src) == as_rate(src, src):
            method = "keyframe"
        w, h = size if size is not None else b["image_size"]
        return Condition(
            factor,
            rs,
            method,
            int(w),
            int(h),
            b["view"] if view is None else view,
            int(b["compression"] if comp is None else comp),
            float(b["noise"] if noise is None else noise),
        )

    out = [make("baseline")]
    out += [make("frame_rate", rate=r, method=m) for r in cfg.frame_rates for m in cfg.resampling]
    out += [make("image_size", size=s) for s in cfg.image_sizes]
    out += [make("view", view=v) for v in cfg.views]
    out += [make("cameras", view=v) for v in cfg.cameras]
    out += [make("compression", comp=q) for q in cfg.compression]
    out += [make("noise", noise=n) for n in cfg.noise]
    seen, unique = set(), []
    for c in out:
        if c.params() not in seen:
            seen.add(c.params())
            unique.append(c)
    return unique


def phrase_complexity(phrases: dict) -> dict[str, str]:
    """Easy / medium / hard by gesture symbols per beat (Neagle's three levels).

    A phrase's own ``complexity`` attribute wins when it has one; otherwise
    the phrases are ranked by how many gesture symbols they pack into a
    beat and split into thirds.

    Parameters
    ----------
    phrases : dict
        name → Score.
    """
    levels = ("easy", "medium", "hard")
    out = {}
    dens = {}
    for name, sc in phrases.items():
        own = getattr(sc, "complexity", None)
        if own in levels:
            out[name] = own
            continue
        n = sum(1 for s in sc.symbols if not s.is_support)
        dens[name] = n / max(float(sc.duration), 1e-9)
    ranked = sorted(dens, key=lambda k: (dens[k], k))
    for i, name in enumerate(ranked):
        out[name] = levels[min(i * 3 // max(len(ranked), 1), 2)]
    return out


def build_jobs(cfg: StudyConfig, phrase_names, complexity: dict, conditions=None) -> list[Job]:
    """Test takes under every condition; training takes under the baseline (the first condition) only."""
    conds = build_conditions(cfg) if conditions is None else list(conditions)
    jobs = []
    for ph in phrase_names:
        for em in cfg.emotions:
            for k in range(cfg.takes):
                perf = Performance(ph, complexity[ph], em, k, "test")
                jobs += [Job(c, perf) for c in conds]
            for k in range(cfg.training_takes):
                perf = Performance(ph, complexity[ph], em, k, "train")
                jobs.append(Job(conds[0], perf))
    return jobs


def take_variation(perf: Performance, seed: int) -> dict:
    """The seeded variation of one take: tempo (bpm), Effort and body height.

    Returns
    -------
    dict
        ``tempo`` (Fraction, bpm, to 1/100), ``effort`` (Effort) and
        ``height`` (m); the same performance and seed always give the same.
    """
    if perf.emotion not in PRESETS:
        raise PipelineError(f"performance {perf}: unknown emotion {perf.emotion!r}")
    rng = np.random.default_rng(stable_seed("take", seed, perf.phrase, perf.emotion, perf.take, perf.split))
    p = PRESETS[perf.emotion]
    tempo = float(p.tempo) * float(np.exp(rng.normal(0.0, VARIATION["log_tempo"])))
    time = float(np.clip(p.effort.time + rng.normal(0.0, VARIATION["time"]), -5.0, -1.5))
    weight = float(np.clip(p.effort.weight + rng.normal(0.0, VARIATION["weight"]), 0.05, 0.95))
    space = float(np.clip(p.effort.space + rng.normal(0.0, VARIATION["space"]), 0.0, 1.0))
    height = float(rng.uniform(*VARIATION["height"]))
    return {
        "tempo": Fraction(round(tempo * 100), 100),
        "effort": Effort(time=round(time, 4), weight=round(weight, 4), space=round(space, 4)),
        "height": round(height, 4),
    }
