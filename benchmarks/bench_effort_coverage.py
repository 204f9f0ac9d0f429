"""Honest Effort and emotion — prints interval coverage per region and the emotion reliability table.

Part 1, coverage: random port-de-bras phrases (``synthetic.port_de_bras``,
both arms, a held support) performed by the virtual dancer at 25 Hz with a
known Effort drawn in each region of the working range — b in three bands of
[−5, −1.5], x0 in three bands of [0.3, 0.8], movements of ½, 1, 2 and 4
beats at 60 bpm — and read back by ``estimate_effort``.  The joints carry a
stated noise model of a fitted capture (:func:`noisy`): white jitter of
``--white-mm`` plus a smooth AR(1) error of ``--smooth-mm`` with frame
correlation ``--rho`` per joint coordinate.  Printed: how often the
movements' 90 % intervals of b and x0 contain the truth, per region.

Part 2, emotion reliability: performers of the four presets (each varying
about its preset by ``emotion.PERFORMER_SD``) dance random port-de-bras
phrases with the same noise.  A fitting set (``--fit-seed``) fits the
temperature of :func:`emotion_probabilities` (``--derive`` prints the
``TEMPERATURE`` constant); a fresh test set (``--test-seed``) gives the
reliability table: for claims binned by their probability, the mean claim
and how often the claimed emotion was right, plus accuracy and how many
performances the domain check refused.

Usage::

    .venv/bin/python benchmarks/bench_effort_coverage.py [--n 1] [--emotion-n 12] [--derive] [--skip-coverage]
"""

from __future__ import annotations

import argparse
import itertools
import time
from fractions import Fraction

import numpy as np

from capture2notation.effort import estimate_effort
from capture2notation.effort.emotion import PERFORMER_SD, TEMPERATURE, emotion_log_likelihoods
from capture2notation.effort.estimate import _emotion_input
from capture2notation.effort.likelihood import CAPTURE_RHO_RANGE
from capture2notation.notation.effort import PRESETS
from capture2notation.notation.model import Effort
from synthetic.interpret import interpret
from synthetic.port_de_bras import random_port_de_bras

FPS = 25.0
EMOTIONS = tuple(PRESETS)
B_BANDS = ((-5.0, -3.83), (-3.83, -2.67), (-2.67, -1.5))
X0_BANDS = ((0.3, 0.467), (0.467, 0.633), (0.633, 0.8))
BEATS = (Fraction(1, 2), Fraction(1), Fraction(2), Fraction(4))
#: Noise model of a fitted capture (set from the command line).
NOISE = {"white": 0.005, "smooth": 0.010, "rho": 0.9}
#: Options of ``estimate_effort`` under test (set from the command line):
#: ``refine`` moves each window's edges onto the measured start and stop,
#: ``max_points`` caps a curve's samples.
ESTIMATE: dict = {}


def noisy(joints: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """`joints` plus white jitter and a stationary AR(1) error along time, per joint coordinate."""
    T = joints.shape[0]
    rho, sd = NOISE["rho"], NOISE["smooth"]
    e = np.empty_like(joints)
    e[0] = sd * rng.standard_normal(joints.shape[1:])
    innov = sd * np.sqrt(1 - rho**2) * rng.standard_normal(joints.shape)
    for t in range(1, T):
        e[t] = rho * e[t - 1] + innov[t]
    return joints + e + NOISE["white"] * rng.standard_normal(joints.shape)


def _inside(summary: dict, truth: float) -> bool:
    lo, hi = summary["ci90"]
    return lo <= truth <= hi


def coverage(n: int, seed: int) -> None:
    """Part 1: per region, % of movement intervals containing the truth."""
    rng = np.random.default_rng(seed)
    rows = []
    t0 = time.perf_counter()
    for (bl, bh), (xl, xh), beats in itertools.product(B_BANDS, X0_BANDS, BEATS):
        for _ in range(n):
            eff = Effort(float(rng.uniform(bl, bh)), float(rng.uniform(xl, xh)), 1.0)
            score = random_port_de_bras(rng, 2, tempo=60, effort=eff, beats=(beats,), head=0.0)
            joints = noisy(interpret(score, fps=FPS).joints(), rng)
            res = estimate_effort(joints, None, FPS, score, rng=rng, **ESTIMATE)
            for m in res.movements:
                s0, s1 = m.posterior.summary(0), m.posterior.summary(1)
                rows.append(
                    (
                        bl,
                        xl,
                        float(beats),
                        _inside(s0, eff.time),
                        _inside(s1, eff.weight),
                        s0["median"] - eff.time,
                        s1["median"] - eff.weight,
                        s0["ci90"][1] - s0["ci90"][0],
                        s1["ci90"][1] - s1["ci90"][0],
                    )
                )
    r = np.array(rows, dtype=float)
    print(
        f"\n== 90 % interval coverage, movements from the dancer's joints + noise "
        f"(white {NOISE['white'] * 1e3:g} mm, AR(1) {NOISE['smooth'] * 1e3:g} mm rho {NOISE['rho']:g}); "
        f"{len(r)} movements, {time.perf_counter() - t0:.0f} s =="
    )
    print(f"  all: b {100 * r[:, 3].mean():.1f} %   x0 {100 * r[:, 4].mean():.1f} %   (aim 85-95 %)")

    def line(label, mask):
        k = r[mask]
        print(
            f"  {label:<22} n={len(k):3d}  b {100 * k[:, 3].mean():5.1f} %  x0 {100 * k[:, 4].mean():5.1f} %  "
            f"bias b {np.median(k[:, 5]):+.2f} x0 {np.median(k[:, 6]):+.3f}  width b {np.median(k[:, 7]):.2f} "
            f"x0 {np.median(k[:, 8]):.3f}"
        )

    for bl, bh in B_BANDS:
        line(f"b {bl:g}..{bh:g}", r[:, 0] == bl)
    for xl, xh in X0_BANDS:
        line(f"x0 {xl:g}..{xh:g}", r[:, 1] == xl)
    for beats in BEATS:
        line(f"{beats} beat movements", r[:, 2] == float(beats))


def _performer(rng: np.random.Generator, emotion: str):
    p, sd = PRESETS[emotion], PERFORMER_SD
    b = float(np.clip(p.effort.time + sd[0] * rng.standard_normal(), -4.9, -1.6))
    x0 = float(np.clip(p.effort.weight + sd[1] * rng.standard_normal(), 0.1, 0.9))
    s = float(np.clip(p.effort.space + sd[2] * rng.standard_normal(), 0.0, 1.0))
    tempo = float(p.tempo) * float(np.exp(sd[3] * rng.standard_normal()))
    return Effort(b, x0, s), Fraction(round(tempo * 4), 4)


def emotion_set(n_per: int, seed: int) -> list:
    """(emotion, log-likelihoods (4,), inside the domain) of `n_per` performers per emotion."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n_per * len(EMOTIONS)):
        emotion = EMOTIONS[k % len(EMOTIONS)]
        effort, tempo = _performer(rng, emotion)
        score = random_port_de_bras(rng, 3, tempo=tempo, effort=effort)
        joints = noisy(interpret(score, fps=FPS).joints(), rng)
        res = estimate_effort(joints, None, FPS, score, rng=rng, per_movement=False)
        x, sd = _emotion_input(res.pooled, res.tempo)
        out.append((emotion, emotion_log_likelihoods(x, sd), res.domain.inside))
    return out


def _probs(ll: np.ndarray, temperature: float) -> np.ndarray:
    z = ll / temperature
    p = np.exp(z - z.max(axis=1, keepdims=True))
    return p / p.sum(axis=1, keepdims=True)


def fit_temperature(cal: list) -> float:
    """Temperature minimising the negative log-probability of the true emotions (grid, log-spaced)."""
    ll = np.array([c[1] for c in cal])
    truth = np.array([EMOTIONS.index(c[0]) for c in cal])
    grid = np.exp(np.linspace(np.log(0.2), np.log(20.0), 400))
    nll = [-np.mean(np.log(_probs(ll, t)[np.arange(len(truth)), truth] + 1e-300)) for t in grid]
    return float(grid[int(np.argmin(nll))])


def reliability(test: list, temperature: float) -> None:
    """The reliability table of `test` at `temperature`."""
    ll = np.array([c[1] for c in test])
    truth = np.array([EMOTIONS.index(c[0]) for c in test])
    inside = np.array([c[2] for c in test])
    p = _probs(ll, temperature)
    claim, best = p.max(axis=1), p.argmax(axis=1)
    right = best == truth
    print(f"\n== emotion reliability on fresh seeds, temperature {temperature:.3g}: {len(test)} performances ==")
    print(
        f"  accuracy {100 * right.mean():.1f} %  (chance 25 %); read by the domain check: {100 * inside.mean():.1f} %"
    )
    print("  claim bin     n   mean claim   right   (90 % interval of right)")
    gap = 0.0
    for lo, hi in ((0.25, 0.5), (0.5, 0.7), (0.7, 0.9), (0.9, 1.0001)):
        m = (claim >= lo) & (claim < hi)
        if m.any():
            low, high = _wilson(int(right[m].sum()), int(m.sum()))
            gap += m.sum() * abs(claim[m].mean() - right[m].mean())
            print(
                f"  {lo:.2f}-{min(hi, 1):.2f}  {m.sum():4d}   {100 * claim[m].mean():8.1f} %  {100 * right[m].mean():5.1f} %"
                f"   ({100 * low:.1f}-{100 * high:.1f} %)"
            )
    nll = -np.mean(np.log(p[np.arange(len(truth)), truth] + 1e-300))
    print(
        f"  mean -ln p(true emotion) {nll:.3f}; claim minus right, weighted over the bins {100 * gap / len(test):.1f} points"
    )


def _wilson(k: int, n: int, z: float = 1.645) -> tuple[float, float]:
    """Wilson score interval of a proportion k/n at 90 % (z = 1.645)."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1, help="Performances per region cell (36 cells).")
    ap.add_argument("--emotion-n", type=int, default=12, help="Performers per emotion in each emotion set.")
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--fit-seed", type=int, default=2005)
    ap.add_argument("--test-seed", type=int, default=2026)
    ap.add_argument("--white-mm", type=float, default=5.0)
    ap.add_argument("--smooth-mm", type=float, default=10.0)
    ap.add_argument("--rho", type=float, default=0.9)
    ap.add_argument("--no-refine", action="store_true", help="Keep the score's windows (no edge refinement).")
    ap.add_argument(
        "--rho-prior",
        choices=("default", "capture"),
        default="default",
        help="Prior of the AR(1) rho: RHO_RANGE or CAPTURE_RHO_RANGE (a fitted capture's smooth error).",
    )
    ap.add_argument("--max-points", type=int, help="Most samples per movement curve (default the module's).")
    ap.add_argument("--derive", action="store_true", help="Fit the temperature on the fitting set and use it.")
    ap.add_argument("--skip-coverage", action="store_true")
    ap.add_argument("--skip-emotion", action="store_true")
    a = ap.parse_args(argv)
    NOISE.update(white=a.white_mm / 1e3, smooth=a.smooth_mm / 1e3, rho=a.rho)
    if a.no_refine:
        ESTIMATE["refine"] = False
    if a.rho_prior == "capture":
        ESTIMATE["sampler_kw"] = {"rho_range": CAPTURE_RHO_RANGE}
    if a.max_points:
        ESTIMATE["max_points"] = a.max_points
    if not a.skip_coverage:
        coverage(a.n, a.seed)
    if not a.skip_emotion:
        temperature = TEMPERATURE
        if a.derive:
            t0 = time.perf_counter()
            cal = emotion_set(a.emotion_n, a.fit_seed)
            temperature = fit_temperature(cal)
            print(
                f"\nfitting set (seed {a.fit_seed}, {len(cal)} performances, {time.perf_counter() - t0:.0f} s): "
                f"TEMPERATURE = {temperature:.3g}"
            )
            reliability(cal, 1.0)
        test = emotion_set(a.emotion_n, a.test_seed)
        reliability(test, 1.0)
        reliability(test, temperature)


if __name__ == "__main__":
    main()
