"""Configuration of a fidelity study: ``study.toml`` (read with :mod:`tomllib`), defaults, ``--quick``.

The study varies one factor at a time around a baseline recording (the
thesis varied size and frame rate in separate experiments too): frame rate
× resampling method, image size, viewpoint, compression and pixel noise.
Every factor level is applied to every performance (phrase × emotion ×
take).  Example ``study.toml``::

    seed = 7
    phrases = ["port_de_bras", "developpe"]   # default: all built-in phrases
    emotions = ["happy", "sad", "angry", "afraid"]
    takes = 3                # test performances per phrase and emotion
    training_takes = 3       # separate performances that calibrate the observer
    capture = "auto"         # "truth", "keypoints", "video", "auto", or "keypoints-calibrated"/"video-calibrated"
    frame_rates = [25, 12.5, 8.33, 5]
    resampling = ["keyframe", "naive"]
    image_sizes = [[220, 175], [320, 240], [640, 480], [1280, 720]]
    views = ["front", "45", "side"]
    compression = [0, 60, 20]  # JPEG quality; 0 = none
    noise = [0, 2, 5]          # pixel noise sigma
    [baseline]
    frame_rate = 25
    image_size = [640, 480]
    view = "front"
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, replace
from pathlib import Path

import tomllib

from capture2notation.compare.resample import as_rate
from capture2notation.errors import PipelineError
from capture2notation.notation.model import EMOTIONS

__all__ = ["StudyConfig", "load_config", "quick"]

CAPTURES = ("auto", "truth", "keypoints", "video", "keypoints-calibrated", "video-calibrated")
RESAMPLING = ("keyframe", "naive")
VIEWS = ("front", "45", "side")


@dataclass(frozen=True)
class StudyConfig:
    """Everything that determines a study's results (with the code version).

    Attributes
    ----------
    seed : int
        Root of every random draw.
    phrases : tuple of str
        Built-in phrase names; empty = all built-in phrases.
    emotions : tuple of str
    takes, training_takes : int
        Test performances per phrase × emotion (>= 2 so a "same" trial shows
        two different takes), and separate ones for calibrating the observer.
    capture : str
        How a condition is captured (see :mod:`pipelines.fidelity.conditions`).
    frame_rates : tuple of float
        Hz, from the 25 Hz source.
    resampling : tuple of str
        ``keyframe`` (Neagle eq. 3.1) and/or ``naive`` decimation.
    image_sizes : tuple of (int, int)
        (width, height) pixels.
    views : tuple of str
    compression : tuple of int
        JPEG quality 1–100; 0 = uncompressed.
    noise : tuple of float
        Pixel noise standard deviation (grey levels for video, pixels of
        keypoint jitter otherwise).
    baseline : dict
        ``frame_rate``, ``image_size``, ``view``, ``compression``, ``noise``
        of the reference recording the factors vary around.
    source_fps : float
        The virtual dancer's frame rate (the thesis' 25 Hz video).
    bootstrap : int
        Resamples of the movements for Effort intervals.
    """

    seed: int = 0
    phrases: tuple = ()
    emotions: tuple = EMOTIONS
    takes: int = 3
    training_takes: int = 3
    capture: str = "auto"
    frame_rates: tuple = (25.0, 12.5, 8.33, 5.0)
    resampling: tuple = RESAMPLING
    image_sizes: tuple = ((220, 175), (320, 240), (640, 480), (1280, 720))
    views: tuple = VIEWS
    compression: tuple = (0, 60, 20)
    noise: tuple = (0.0, 2.0, 5.0)
    baseline: dict = field(
        default_factory=lambda: {
            "frame_rate": 25.0,
            "image_size": (640, 480),
            "view": "front",
            "compression": 0,
            "noise": 0.0,
        }
    )
    source_fps: float = 25.0
    bootstrap: int = 30

    def __post_init__(self):
        where = "study config"
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise PipelineError(f"{where}: seed must be a non-negative integer, got {self.seed!r}")
        for e in self.emotions:
            if e not in EMOTIONS:
                raise PipelineError(f"{where}: unknown emotion {e!r}; expected some of {', '.join(EMOTIONS)}")
        if len(self.emotions) < 2:
            raise PipelineError(f"{where}: same/different trials need at least 2 emotions, got {list(self.emotions)}")
        if self.takes < 2 or self.training_takes < 2:
            raise PipelineError(
                f"{where}: takes and training_takes must be >= 2, got {self.takes}, {self.training_takes}"
            )
        if self.capture not in CAPTURES:
            raise PipelineError(f"{where}: capture {self.capture!r} must be one of {', '.join(CAPTURES)}")
        for m in self.resampling:
            if m not in RESAMPLING:
                raise PipelineError(f"{where}: resampling {m!r} must be one of {', '.join(RESAMPLING)}")
        for v in self.views:
            if v not in VIEWS:
                raise PipelineError(f"{where}: view {v!r} must be one of {', '.join(VIEWS)}")
        for r in self.frame_rates:
            if not 0 < float(r) <= self.source_fps:
                raise PipelineError(f"{where}: frame rate {r} Hz must lie in (0, {self.source_fps}]")
        for s in self.image_sizes:
            if len(s) != 2 or min(s) < 16:
                raise PipelineError(f"{where}: image size {list(s)} must be [width, height] of at least 16 px")
        for q in self.compression:
            if not (q == 0 or 1 <= q <= 100):
                raise PipelineError(f"{where}: compression quality {q} must be 0 (none) or 1-100")
        for n in self.noise:
            if not float(n) >= 0:
                raise PipelineError(f"{where}: noise sigma {n} must be >= 0")
        b = self.baseline
        missing = {"frame_rate", "image_size", "view", "compression", "noise"} - set(b)
        if missing:
            raise PipelineError(f"{where}: baseline lacks {', '.join(sorted(missing))}")
        if b["view"] not in VIEWS:
            raise PipelineError(f"{where}: baseline view {b['view']!r} must be one of {', '.join(VIEWS)}")
        as_rate(b["frame_rate"], self.source_fps)

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}


def _tuplify(v):
    if isinstance(v, list):
        return tuple(_tuplify(x) for x in v)
    return v


def load_config(path=None, overrides: dict | None = None) -> StudyConfig:
    """Read ``study.toml`` (or the defaults) and apply `overrides`.

    Unknown keys are an error (a typo would otherwise silently change nothing).

    Parameters
    ----------
    path : str or Path, optional
    overrides : dict, optional
        Field → value, applied after the file.
    """
    data: dict = {}
    if path is not None:
        p = Path(path)
        try:
            data = tomllib.loads(p.read_text(encoding="utf-8"))
        except OSError as exc:
            raise PipelineError(f"{p}: cannot read the study config ({exc.strerror})") from None
        except tomllib.TOMLDecodeError as exc:
            raise PipelineError(f"{p}: not valid TOML: {exc}") from None
    data.update(overrides or {})
    known = {f.name for f in dataclasses.fields(StudyConfig)}
    unknown = sorted(set(data) - known)
    if unknown:
        where = str(path) if path is not None else "study config"
        raise PipelineError(
            f"{where}: unknown setting(s) {', '.join(unknown)}; expected some of {', '.join(sorted(known))}"
        )
    kw = {}
    for k, v in data.items():
        if k == "baseline":
            base = dict(StudyConfig().baseline)
            base.update({bk: _tuplify(bv) for bk, bv in dict(v).items()})
            kw[k] = base
        else:
            kw[k] = _tuplify(v)
    return StudyConfig(**kw)


def quick(cfg: StudyConfig, phrases: tuple = ()) -> StudyConfig:
    """The ``--quick`` study: a tiny grid that still exercises every factor.

    Two phrases (first two of `phrases` when none are configured), two takes,
    the extreme levels of each factor; the capture path is the config's
    (``auto``: the keypoint path with 3D fitting, about a minute on 2 cores).
    """

    def ends(seq):
        seq = tuple(seq)
        return seq if len(seq) <= 2 else (seq[0], seq[-1])

    return replace(
        cfg,
        phrases=tuple(cfg.phrases or phrases)[:2],
        takes=2,
        training_takes=2,
        frame_rates=ends(cfg.frame_rates),
        image_sizes=ends(cfg.image_sizes),
        views=ends(cfg.views),
        compression=ends(cfg.compression),
        noise=ends(cfg.noise),
        bootstrap=min(cfg.bootstrap, 10),
    )
