"""Configuration of a fidelity study: ``study.toml`` (read with :mod:`tomllib`), defaults, ``--quick``.

The study varies one factor at a time around a baseline recording (the
thesis varied size and frame rate in separate experiments too): frame rate
× resampling method, image size, viewpoint, the number and placement of
calibrated cameras, compression and pixel noise.
Every factor level is applied to every performance (phrase × emotion ×
take).  Example ``study.toml``::

    seed = 7
    phrases = ["port_de_bras", "developpe"]   # default: all built-in phrases
    emotions = ["happy", "sad", "angry", "afraid"]
    takes = 3                # test performances per phrase and emotion
    training_takes = 3       # separate performances that calibrate the observer
    capture = "auto"         # a capture path or a list of them, e.g. ["video", "keypoints"]
    frame_rates = [25, 12.5, 8.33, 5]
    resampling = ["keyframe", "naive"]
    image_sizes = [[220, 175], [320, 240], [640, 480], [1280, 720]]
    views = ["front", "45", "side"]
    cameras = ["front+side", "45+-45", "front+45+side"]   # calibrated cameras filming at once
    compression = [0, 60, 20]  # JPEG quality; 0 = none
    noise = [0, 2, 5]          # pixel noise sigma
    [baseline]
    frame_rate = 25
    image_size = [640, 480]
    view = "front"

Capture paths (:mod:`pipelines.fidelity.measure`): ``video`` (render →
BlazePose → fit, the real perception path), ``keypoints`` (simulated
BlazePose landmarks with Gaussian world-landmark noise → fit: the named fast
condition, about 0.8 s a job against 5 s on the video path), ``truth``, and the calibrated
conditions ``keypoints-calibrated`` / ``video-calibrated``.  ``capture`` is
one of them or a list: every listed path runs the whole grid, the first is
the primary one (the figures and conclusions of the report) and the report
compares the paths condition by condition.  ``auto`` is :data:`AUTO_CAPTURE`:
the video path, with the keypoint path beside it (the full default grid,
816 video and 720 keypoint jobs, took 33 minutes on 2 cores; see
``docs/benchmarks/scale.md``); the ``--quick`` study's ``auto`` is the
keypoint path alone.

Every value is checked for its type and range (:func:`check`): a wrong one
is a one-line error naming the key and the value.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, replace
from pathlib import Path

import tomllib

from capture2notation.compare.resample import as_rate
from capture2notation.errors import PipelineError
from capture2notation.notation.model import EMOTIONS

__all__ = [
    "AUTO_CAPTURE",
    "CAPTURES",
    "QUICK_AUTO_CAPTURE",
    "StudyConfig",
    "check",
    "expand_capture",
    "load_config",
    "quick",
]

#: What ``capture = "auto"`` runs: the real video path, compared with the simulated-keypoint path.
AUTO_CAPTURE = ("video", "keypoints")
#: What ``capture = "auto"`` runs in the ``--quick`` study: the fast path alone.
QUICK_AUTO_CAPTURE = ("keypoints",)
CAPTURES = ("auto", "truth", "keypoints", "video", "keypoints-calibrated", "video-calibrated")
RESAMPLING = ("keyframe", "naive")
VIEWS = ("front", "45", "side")
#: Views a camera of a several-camera condition may take (the renderer's).
CAMERA_VIEWS = ("front", "45", "side", "-45")


def _is_cameras(x) -> bool:
    """Two or more distinct views of :data:`CAMERA_VIEWS` joined by ``+``."""
    parts = x.split("+") if isinstance(x, str) else []
    return len(parts) >= 2 and len(set(parts)) == len(parts) and all(p in CAMERA_VIEWS for p in parts)


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
    capture : str or tuple of str
        How a condition is captured: one path of :data:`CAPTURES` or several
        (the first is the primary one).
    frame_rates : tuple of float
        Hz, from the 25 Hz source.
    resampling : tuple of str
        ``keyframe`` (Neagle eq. 3.1) and/or ``naive`` decimation.
    image_sizes : tuple of (int, int)
        (width, height) pixels.
    views : tuple of str
    cameras : tuple of str
        Several calibrated cameras filming at once, their views joined by
        ``+`` (e.g. ``front+side``), triangulated (:mod:`pipelines.capture_multi`):
        what a second or third camera buys over the baseline's one.
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
    capture: str | tuple = "auto"
    frame_rates: tuple = (25.0, 12.5, 8.33, 5.0)
    resampling: tuple = RESAMPLING
    image_sizes: tuple = ((220, 175), (320, 240), (640, 480), (1280, 720))
    views: tuple = VIEWS
    cameras: tuple = ("front+side", "45+-45", "front+45+side")
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
        if isinstance(self.capture, (list, tuple)):
            object.__setattr__(self, "capture", tuple(self.capture))
        check(self)

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _seq(v) -> bool:
    return isinstance(v, (tuple, list))


#: Per list-valued key: (test of one element, what it must be).
LIST_KEYS = {
    "phrases": (lambda x: isinstance(x, str), "a list of phrase names"),
    "emotions": (lambda x: x in EMOTIONS, f"a list of emotions out of {', '.join(EMOTIONS)}"),
    "resampling": (lambda x: x in RESAMPLING, f"a list out of {', '.join(RESAMPLING)}"),
    "views": (lambda x: x in VIEWS, f"a list out of {', '.join(VIEWS)}"),
    "cameras": (_is_cameras, f"a list of two or more views joined by '+' (views out of {', '.join(CAMERA_VIEWS)})"),
    "frame_rates": (lambda x: _is_num(x) and x > 0, "a list of frame rates in Hz (numbers > 0)"),
    "image_sizes": (
        lambda x: _seq(x) and len(x) == 2 and all(_is_int(n) and n >= 16 for n in x),
        "a list of [width, height] pairs of integers >= 16 px",
    ),
    "compression": (lambda x: _is_int(x) and (x == 0 or 1 <= x <= 100), "a list of JPEG qualities 1-100 (0 = none)"),
    "noise": (lambda x: _is_num(x) and x >= 0, "a list of pixel noise sigmas (numbers >= 0)"),
}
#: Per integer key: its least value and why.
INT_KEYS = {"seed": 0, "takes": 2, "training_takes": 2, "bootstrap": 0}


def check(cfg: StudyConfig, where: str = "study config") -> None:
    """Raise a one-line :class:`PipelineError` naming the first key of the wrong type or range and its value."""

    def bad(key, must, value):
        raise PipelineError(f"{where}: {key} must be {must}, got {value!r}")

    for key, least in INT_KEYS.items():
        v = getattr(cfg, key)
        if not _is_int(v) or v < least:
            # takes >= 2 so that a "same" trial shows two different takes.
            bad(key, f"an integer >= {least}", v)
    if not _is_num(cfg.source_fps) or not cfg.source_fps > 0:
        bad("source_fps", "a number > 0 (Hz)", cfg.source_fps)
    modes = (cfg.capture,) if isinstance(cfg.capture, str) else cfg.capture
    must = f"one of {', '.join(CAPTURES)} or a list of them"
    if not _seq(modes) or not modes:
        bad("capture", must, cfg.capture)
    for m in modes:
        if not (isinstance(m, str) and m in CAPTURES):
            bad("capture", must, m)
    for key, (ok, must) in LIST_KEYS.items():
        v = getattr(cfg, key)
        if not _seq(v):
            bad(key, must, v)
        for x in v:
            if not ok(x):
                bad(key, must, x)
    if len(cfg.emotions) < 2:
        bad("emotions", "at least 2 emotions (same/different trials)", list(cfg.emotions))
    for r in cfg.frame_rates:
        if r > cfg.source_fps:
            bad("frame_rates", f"at most the source rate {cfg.source_fps:g} Hz", r)
    b = cfg.baseline
    if not isinstance(b, dict):
        bad("baseline", "a table (frame_rate, image_size, view, compression, noise)", b)
    unknown = sorted(set(b) - set(BASELINE_KEYS))
    if unknown:
        bad("baseline", f"a table of {', '.join(BASELINE_KEYS)} only (unknown: {', '.join(unknown)})", b)
    missing = sorted(set(BASELINE_KEYS) - set(b))
    if missing:
        bad("baseline", f"a table with {', '.join(missing)} too", b)
    for key in BASELINE_KEYS:
        ok, must = LIST_KEYS[BASELINE_KEYS[key]]
        if not ok(b[key]):
            bad(f"baseline.{key}", must.replace("a list of ", "").replace("a list out of ", "one of "), b[key])
    if b["frame_rate"] > cfg.source_fps:
        bad("baseline.frame_rate", f"at most the source rate {cfg.source_fps:g} Hz", b["frame_rate"])
    try:
        as_rate(b["frame_rate"], cfg.source_fps)
    except PipelineError as exc:
        raise PipelineError(f"{where}: baseline.frame_rate: {exc}") from None


#: Baseline key → the list key whose element rules it follows.
BASELINE_KEYS = {
    "frame_rate": "frame_rates",
    "image_size": "image_sizes",
    "view": "views",
    "compression": "compression",
    "noise": "noise",
}


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
    where = str(path) if path is not None else "study config"
    known = {f.name for f in dataclasses.fields(StudyConfig)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise PipelineError(
            f"{where}: unknown setting(s) {', '.join(unknown)}; expected some of {', '.join(sorted(known))}"
        )
    kw = {}
    for k, v in data.items():
        if k == "baseline":
            if not isinstance(v, dict):
                raise PipelineError(f"{where}: baseline must be a table ([baseline] in study.toml), got {v!r}")
            base = dict(StudyConfig().baseline)
            base.update({bk: _tuplify(bv) for bk, bv in v.items()})
            kw[k] = base
        else:
            kw[k] = _tuplify(v)
    try:
        return StudyConfig(**kw)
    except PipelineError as exc:
        msg = str(exc)
        raise PipelineError(where + msg[len("study config") :] if msg.startswith("study config") else msg) from None


def expand_capture(capture, auto: tuple = AUTO_CAPTURE) -> tuple[str, ...]:
    """The capture paths a ``capture`` value names, the primary first, ``auto`` replaced by `auto`, each once."""
    modes = (capture,) if isinstance(capture, str) else tuple(capture)
    return tuple(dict.fromkeys(m for mode in modes for m in (auto if mode == "auto" else (mode,))))


def quick(cfg: StudyConfig, phrases: tuple = ()) -> StudyConfig:
    """The ``--quick`` study: a tiny grid that still exercises every factor.

    Two phrases (first two of `phrases` when none are configured), two takes,
    the extreme levels of each factor; the capture path is the config's
    (``auto``: :data:`QUICK_AUTO_CAPTURE`, the keypoint path with 3D fitting,
    about a minute on 2 cores).
    """
    modes = expand_capture(cfg.capture, QUICK_AUTO_CAPTURE)

    def ends(seq):
        seq = tuple(seq)
        return seq if len(seq) <= 2 else (seq[0], seq[-1])

    return replace(
        cfg,
        phrases=tuple(cfg.phrases or phrases)[:2],
        capture=modes[0] if len(modes) == 1 else modes,
        takes=2,
        training_takes=2,
        frame_rates=ends(cfg.frame_rates),
        image_sizes=ends(cfg.image_sizes),
        views=ends(cfg.views),
        cameras=ends(cfg.cameras),
        compression=ends(cfg.compression),
        noise=ends(cfg.noise),
        bootstrap=min(cfg.bootstrap, 10),
    )
