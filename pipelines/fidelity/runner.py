"""Run a fidelity study: every job in parallel, cached, then the same/different trials.

Jobs run on local processes by default (one per core, with a progress bar)
or on a Dask distributed cluster (``scheduler`` address), see :mod:`.pool`.
Each job is cached atomically as ``cache/<hash>.json`` in the output folder
as soon as it finishes, the hash covering the job's whole configuration and
the code version, so an interrupted study resumes where it stopped; a cache
file that is not such a row is rerun with a warning.  Every random draw is seeded from the study seed
and the job's identity (not its position in a queue), so the same seed gives
the same ``results.csv`` however the jobs are scheduled.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
import os
import signal
import time
from dataclasses import asdict
from fractions import Fraction
from pathlib import Path

import numpy as np

from capture2notation import __version__
from capture2notation.atomic import write_text
from capture2notation.compare.discrimination import (
    SameDifferentObserver,
    experiment1_trials,
    experiment2_trials,
    feature_vector,
    run_trials,
    summarise,
)
from capture2notation.errors import C2NError, PipelineError

from .conditions import Condition, Job, build_conditions, build_jobs, phrase_complexity, stable_seed
from .config import StudyConfig, expand_capture
from .measure import builtin_scores, capture, kept_frames, measure, perform
from .pool import StudyInterrupted, _Stop, execute, signal_of, stop_on_signals

__all__ = [
    "STUDY_VERSION",
    "StudyInterrupted",
    "StudyResult",
    "load_cached",
    "resolve_capture",
    "run_condition",
    "run_study",
]

log = logging.getLogger(__name__)

#: Bumped when the measurement changes, so cached jobs are recomputed.
STUDY_VERSION = f"{__version__}-fidelity-6"

#: Capture paths without images (compression cannot be applied).
IMAGE_FREE = ("truth", "keypoints")

#: Columns of results.csv, in order (one row per job).
ID_COLUMNS = (
    "factor",
    "frame_rate",
    "resampling",
    "width",
    "height",
    "view",
    "compression",
    "noise",
    "phrase",
    "complexity",
    "emotion",
    "take",
    "split",
    "capture",
)


def resolve_capture(capture) -> tuple[str, ...]:
    """The capture paths to run, the primary first: ``auto`` is :data:`~.config.AUTO_CAPTURE`."""
    return expand_capture(capture)


def run_condition(
    job: Job, seed: int, capture_mode="truth", fps: float = 25.0, bootstrap: int = 30, scores=None, threads: int = 2
) -> dict:
    """Perform, record, capture and measure one job.

    Parameters
    ----------
    job : Job
        A performance under a condition.
    seed : int
        Study seed.
    capture_mode : str or callable
        ``"truth"``, ``"keypoints"``, ``"video"``, or a function ``(motion, kept, condition,
        rng) -> (joints (T,J,3), confidence (T,J))`` (the pluggable capture).
    fps : float
        The virtual dancer's frame rate.
    bootstrap : int
        Resamples for the Effort intervals.
    scores : dict, optional
        Phrase name → Score (default: the built-in phrases).
    threads : int
        The pose model's threads on the video path (the result does not depend on it).

    Returns
    -------
    dict
        The job's identity columns and its metrics; ``error`` is the message
        of a failure (metrics then absent), never a silent default.
    """
    c, p = job.condition, job.performance
    row = dict(asdict(c).items()) | asdict(p)
    row["capture"] = capture_mode if isinstance(capture_mode, str) else getattr(capture_mode, "__name__", "custom")
    rng = np.random.default_rng(stable_seed("job", seed, *c.params(), *asdict(p).values()))
    t0 = time.perf_counter()
    try:
        score, motion = perform(p, seed, fps, scores)
        kept = kept_frames(c, score, motion.n_frames, motion.fps)
        if callable(capture_mode):
            joints, conf = capture_mode(motion, kept, c, rng)
        else:
            joints, conf = capture(capture_mode, motion, kept, c, rng, threads)
        row.update(measure(score, motion, joints, conf, kept, rng, bootstrap))
        row["error"] = ""
    except C2NError as exc:
        row["error"] = f"{type(exc).__name__}: {exc}"
    row["seconds"] = time.perf_counter() - t0
    return row


def _job_cost(mode: str, job: Job, scores: dict) -> float:
    """A job's relative cost for scheduling: the phrase's beats, times the image's pixels on the video path.

    Rendering, decoding and encoding grow with the pixels; the pose model
    and the fit do not (a 1280×720 job costs about 2.5 times a 640×480 one).
    """
    beats = float(scores[job.performance.phrase].duration)
    if not mode.startswith("video"):
        return beats
    return beats * (1.0 + job.condition.width * job.condition.height / (640 * 480))


def _job_worker(args):
    # OpenCV's thread count is left alone: resizing its pool in a forked
    # worker waits for threads that stayed in the parent.
    job, seed, mode, fps, bootstrap, digest, threads = args
    return run_condition(job, seed, mode, fps, bootstrap, threads=threads) | {"job": digest}


class StudyResult:
    """Rows of a finished study and its discrimination summary.

    ``rows``, ``trials``, ``summary`` and ``conditions`` are those of the
    primary (first) capture path; ``by_capture`` maps every capture path run
    to its own ``(rows, trials, summary, conditions)``.
    """

    def __init__(self, rows, trials, summary, conditions, wall_seconds, by_capture=None):
        self.rows = rows
        self.trials = trials
        self.summary = summary
        self.conditions = conditions
        self.wall_seconds = wall_seconds
        self.by_capture = by_capture or {summary.get("capture"): (rows, trials, summary, conditions)}


def _cache_path(outdir: Path, digest: str) -> Path:
    return outdir / "cache" / f"{digest}.json"


#: Keys every cached result row carries (the job's identity, its outcome, its cache key).
ROW_KEYS = frozenset(ID_COLUMNS) - {"factor"} | {"error", "seconds", "job"}


def load_cached(path: Path, digest: str, job: Job, mode: str) -> dict | None:
    """The cached row of a job, or None (with a warning) when the file cannot be trusted.

    A file that is not JSON, JSON that is not a result row, or a row of
    another job, configuration or code version (its ``job`` key differs from
    the file's name) is rerun, never used.
    """
    if not path.exists():
        return None
    try:
        row = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        log.warning("cache file %s is unreadable (%s); rerunning its job", path, exc)
        return None
    if not isinstance(row, dict) or not set(row) >= ROW_KEYS:
        what = f"keys {sorted(row)[:6]}" if isinstance(row, dict) else type(row).__name__
        log.warning("cache file %s is not a result row (%s); rerunning its job", path, what)
        return None
    p = job.performance
    mine = row["job"] == digest and row["capture"] == mode
    mine = mine and (row["phrase"], row["emotion"], row["take"], row["split"]) == (p.phrase, p.emotion, p.take, p.split)
    if not mine:
        log.warning("cache file %s holds another job's row (job %r); rerunning its job", path, row["job"])
        return None
    return row


def _stopped(exc: BaseException, outdir: Path, finished: int, total: int) -> StudyInterrupted:
    signum = signal_of(exc)
    name = signal.Signals(signum).name if signum else "signal"
    return StudyInterrupted(
        f"interrupted by {name}: {finished} of {total} jobs are finished and kept in {outdir / 'cache'}; "
        "run the same command again to resume",
        signum or int(signal.SIGINT),
    )


def run_study(
    cfg: StudyConfig,
    outdir,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = True,
    connect_timeout: float = 20.0,
) -> StudyResult:
    """Run (or resume) a study and write ``results.csv``, ``trials.csv`` and ``summary.json``.

    Parameters
    ----------
    cfg : StudyConfig
    outdir : str or Path
    scheduler : str, optional
        Dask scheduler address (``tcp://host:8786``); local processes otherwise.
    workers : int, optional
        Local processes (default: the number of cores).
    progress : bool
        Show a tqdm progress bar.
    connect_timeout : float
        Seconds to wait for the Dask scheduler.

    Raises
    ------
    StudyInterrupted
        On Ctrl-C or SIGTERM, within about a second, after every finished job
        was cached and the worker processes were killed.
    """
    from capture2notation.progress import progress as progress_bar

    t0 = time.perf_counter()
    outdir = Path(outdir)
    modes = resolve_capture(cfg.capture)
    scores = builtin_scores()
    names = tuple(cfg.phrases) or tuple(sorted(scores))
    missing = [n for n in names if n not in scores]
    if missing:
        raise PipelineError(f"unknown phrase(s) {', '.join(missing)}; built-in phrases are {', '.join(sorted(scores))}")
    complexity = phrase_complexity({n: scores[n] for n in (tuple(sorted(scores)))})
    grid = {}
    for mode in modes:
        conditions = build_conditions(cfg)
        if mode in IMAGE_FREE:
            # No image on these paths: a compression level would silently equal the baseline.
            conditions = [c for c in conditions if c.compression == 0]
        grid[mode] = (conditions, build_jobs(cfg, names, complexity, conditions))
    rows_by_job: dict = {}
    pending = []
    for mode, (_conds, jobs) in grid.items():
        for j in jobs:
            digest = j.digest(cfg, mode, STUDY_VERSION)
            row = load_cached(_cache_path(outdir, digest), digest, j, mode)
            if row is None:
                pending.append((mode, j, digest))
            else:
                rows_by_job[(mode, j)] = row
    total = sum(len(jobs) for _c, jobs in grid.values())
    log.info("%d jobs, %d cached, %d to run (capture=%s)", total, total - len(pending), len(pending), ",".join(modes))
    # Longest first, so that no long job starts last and runs alone (the
    # order changes nothing else: each job is seeded by its identity).
    pending.sort(key=lambda item: -_job_cost(item[0], item[1], scores))

    def keep(i, row):
        mode, j, digest = pending[i]
        write_text(_cache_path(outdir, digest), json.dumps(row, sort_keys=True, default=_json_default))
        rows_by_job[(mode, j)] = row

    workers = workers or os.cpu_count() or 1
    # One pose-model thread a job when jobs run side by side (a cluster's or
    # this machine's processes), two when they run one at a time here.
    threads = 1 if scheduler or (workers > 1 and len(pending) > 1) else 2
    args = [(j, cfg.seed, mode, cfg.source_fps, cfg.bootstrap, digest, threads) for mode, j, digest in pending]
    bar = progress_bar(total=len(args), desc="fidelity study", unit="job", enabled=progress)
    try:
        with stop_on_signals():
            execute(
                _job_worker,
                args,
                keep,
                scheduler=scheduler,
                workers=workers,
                timeout=connect_timeout,
                on_progress=bar.update,
            )
    except (KeyboardInterrupt, _Stop) as exc:
        raise _stopped(exc, outdir, len(rows_by_job), total) from None
    finally:
        bar.close()
    by_capture = {}
    for mode, (conditions, jobs) in grid.items():
        # Condition identity (not its factor label) keys the cache; restore the label here.
        rows = [dict(rows_by_job[(mode, j)], factor=j.condition.factor) for j in jobs]
        trials, summary = discrimination(rows, cfg, conditions)
        for t in trials:
            t["capture"] = mode
        summary["config"] = cfg.as_dict()
        summary["capture"] = mode
        summary["jobs"] = {
            "total": len(jobs),
            "ran": sum(1 for m, _j, _d in pending if m == mode),
            "failed": sum(1 for r in rows if r.get("error")),
            "job_seconds": float(sum(r.get("seconds", 0.0) for r in rows)),
        }
        summary["jobs"]["cached"] = len(jobs) - summary["jobs"]["ran"]
        by_capture[mode] = (rows, trials, summary, conditions)
    rows, trials, summary, conditions = by_capture[modes[0]]
    if len(modes) > 1:
        summary["other_captures"] = {m: by_capture[m][2] for m in modes[1:]}
    write_text(outdir / "results.csv", rows_to_csv([r for m in modes for r in by_capture[m][0]]))
    write_text(outdir / "trials.csv", rows_to_csv([t for m in modes for t in by_capture[m][1]]))
    write_text(outdir / "summary.json", json.dumps(summary, indent=2, sort_keys=True, default=_json_default))
    return StudyResult(rows, trials, summary, conditions, time.perf_counter() - t0, by_capture)


def _json_default(o):
    if isinstance(o, Fraction):
        return str(o)
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.floating,)):
        return float(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def _fmt(v) -> str:
    if isinstance(v, bool):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return "nan" if math.isnan(v) else f"{float(v):.6g}"
    return str(v)


def rows_to_csv(rows: list[dict]) -> str:
    """CSV text with a stable column order (identity columns first, then sorted)."""
    if not rows:
        return ""
    cols = [c for c in ID_COLUMNS if any(c in r for r in rows)]
    rest = sorted({k for r in rows for k in r} - set(cols) - {"seconds", "job"})
    cols += rest
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for r in rows:
        w.writerow([_fmt(r.get(c, "")) for c in cols])
    return buf.getvalue()


def _features(r: dict) -> np.ndarray:
    return feature_vector(
        {
            "time": r.get("time_est"),
            "weight": r.get("weight_est"),
            "space": r.get("space_est"),
            "tempo": r.get("tempo_obs"),
        }
    )


def discrimination(rows: list[dict], cfg: StudyConfig, conditions: list[Condition]) -> tuple[list, dict]:
    """Same/different trials per condition (Experiment 1) and over frame rates (Experiment 2).

    The observer is calibrated once, on the training takes recorded under
    the baseline condition; the trials draw only test takes.
    """
    train = [r for r in rows if r["split"] == "train" and not r.get("error")]
    if len(train) < 4:
        raise PipelineError(f"only {len(train)} training performances succeeded; need >= 4 to calibrate the observer")
    obs = SameDifferentObserver.calibrate(np.array([_features(r) for r in train]), [r["emotion"] for r in train])
    test = [r for r in rows if r["split"] == "test" and not r.get("error")]
    by_cond: dict = {}
    for r in test:
        params = (r["frame_rate"], r["resampling"], r["width"], r["height"], r["view"], r["compression"], r["noise"])
        key = (r["emotion"], r["complexity"], Fraction(r["frame_rate"]))
        by_cond.setdefault(params, {}).setdefault(key, []).append(_features(r))
    complexities = tuple(c for c in ("easy", "medium", "hard") if any(r["complexity"] == c for r in test))
    all_trials, per_condition = [], []
    for c in conditions:
        pool = {k: np.array(v) for k, v in by_cond.get(c.params(), {}).items()}
        comps = tuple(
            x
            for x in complexities
            if all((e, x, c.rate) in pool and len(pool[(e, x, c.rate)]) >= 2 for e in cfg.emotions)
        )
        if not comps:
            continue
        trials = experiment1_trials(comps, cfg.emotions, c.rate)
        res = run_trials(trials, pool, obs, np.random.default_rng(stable_seed("trials", cfg.seed, *c.params())))
        for t in res:
            t.update({"experiment": 1, "condition": c.label, "factor": c.factor, "resampling": c.resampling})
        all_trials += res
        s = summarise(res)
        per_condition.append(
            {
                "condition": c.label,
                "factor": c.factor,
                **dict(asdict(c).items()),
                "percent_correct": s["overall"],
                "by_pair": s["by_pair"],
                "by_complexity": s["by_complexity"],
                "by_kind": s["by_kind"],
                "n": s["n"],
            }
        )
    exp2 = {}
    emos2 = tuple(e for e in ("happy", "sad", "angry") if e in cfg.emotions)
    comps2 = tuple(x for x in ("easy", "hard") if x in complexities) or complexities[:1]
    base = conditions[0]
    for method in cfg.resampling:
        pool, rates = {}, []
        for c in conditions:
            if c.factor not in ("baseline", "frame_rate") or c.params()[2:] != base.params()[2:]:
                continue
            if c.resampling != method and c.rate != Fraction(str(cfg.source_fps)):
                continue
            pool.update({k: np.array(v) for k, v in by_cond.get(c.params(), {}).items()})
            rates.append(c.rate)
        rates = sorted(set(rates))
        if len(emos2) < 2 or not rates or not comps2:
            continue
        trials = experiment2_trials(comps2, rates, emos2)
        if not all((t.emotion_a, t.complexity, t.frame_rate) in pool for t in trials):
            continue
        res = run_trials(trials, pool, obs, np.random.default_rng(stable_seed("exp2", cfg.seed, method)))
        for t in res:
            t.update(
                {"experiment": 2, "condition": f"frame rates, {method}", "factor": "frame_rate", "resampling": method}
            )
        all_trials += res
        exp2[method] = summarise(res)
    summary = {"observer": obs.as_dict(), "experiment1": per_condition, "experiment2": exp2}
    return all_trials, summary
