"""The beats of a sound track as evidence on the tempo (librosa, the optional ``audio`` extra).

librosa's beat tracker (onset strength, a tempogram and Ellis's dynamic
programme) finds the beats; each is moved to the onset it stands for, and
a straight line through them (each beat numbered from the tracker's own
period, so a skipped beat does not bend it; beats off the line left out)
gives the tempo to a fraction of a bpm.  The music's beat may be the
dancers' count or half or double it, so the evidence is a mixture over
those metrical levels (:data:`LEVEL_WEIGHTS`), and a small share of it
(:data:`TRACKER_ERROR_RATE`) is spread over every tempo: strong movement
evidence can pick the level, but the sound's period usually wins.

librosa (with numba and scikit-learn: about 300 MB installed, and several
seconds to import) is an optional dependency, ``pip install
'capture2notation[audio]'``.  Without it :func:`sound_beats` raises
:class:`BeatTrackerMissing`, whose message says how to install it; a
capture then estimates the tempo from the movements alone and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import QuantiseError
from ..io.audio import SoundTrack

__all__ = [
    "LEVEL_WEIGHTS",
    "MIN_BEATS",
    "BeatTrackerMissing",
    "SoundBeats",
    "beat_tracker_available",
    "sound_beats",
]

#: Prior probability that the dancers count at half, at, and at double the
#: music's beat.
LEVEL_WEIGHTS = {0.5: 0.1, 1.0: 0.8, 2.0: 0.1}
#: Share of the evidence spread evenly over log-tempo (the tracker locked
#: onto something else than the beat).
TRACKER_ERROR_RATE = 0.05
#: Width (octaves) of that even spread.
_ERROR_SPAN_OCTAVES = 3.0
#: Smallest relative uncertainty of the sound's tempo (a live performance
#: drifts; a click track's line fit is tighter than the candidate grid).
MIN_RELATIVE_SD = 0.005
#: Fewest beats on the line (and the span they cover, in beats + 1) that make a beat.
MIN_BEATS = 4
#: Largest RMS distance of the beats from their line, in periods: more
#: irregular than this is no steady beat.
MAX_IRREGULARITY = 0.12
#: Weakest onset that marks a beat, as a share of the track's strongest.
ONSET_FRACTION = 0.3
#: Share of the beats between the first and the last that must sound.
MIN_COVERAGE = 0.8
#: Quietest sound track analysed: RMS amplitude (full scale 1) below this is silence.
SILENCE_RMS = 1e-3
#: Relative distance within which a tempo is taken as one of the sound's levels.
_SAME = 0.04
#: Hop of the onset envelope, samples (23 ms at 22 050 Hz: librosa's default).
_HOP = 512
#: Silence added before and after the track for the onset analysis, seconds.
_PAD_S = 0.25
#: Window (periods either side) in which a tracked beat looks for its onset.
_SNAP_PERIODS = 0.2
#: Largest distance (periods) of a beat from the line to stay in the fit.
_OUTLIER_PERIODS = 0.15


class BeatTrackerMissing(QuantiseError):
    """librosa is not installed (the optional ``audio`` extra)."""


def beat_tracker_available() -> bool:
    """Whether librosa can be imported."""
    try:
        import librosa  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass(frozen=True)
class SoundBeats:
    """The beat of a sound track.

    Attributes
    ----------
    tempo : float
        Beats per minute of the music's beat (the line fit).
    relative_sd : float
        Standard error of `tempo`, relative (at least :data:`MIN_RELATIVE_SD`).
    beat_times : (B,) ndarray
        The beats on the line, seconds.
    irregularity : float
        RMS distance of those beats from the line, in periods.
    source : str
        ``"the sound track"``, for the page.
    """

    tempo: float
    relative_sd: float
    beat_times: np.ndarray
    irregularity: float
    source: str = "the sound track"

    def log_likelihood(self, tempi) -> np.ndarray:
        """Log density (C,) in log-tempo of candidate tempi (bpm): the mixture of the module docstring."""
        x = np.log(np.asarray(tempi, dtype=float))
        sd = np.log1p(self.relative_sd)
        dens = np.full(x.shape, TRACKER_ERROR_RATE / (_ERROR_SPAN_OCTAVES * np.log(2.0)))
        for level, w in LEVEL_WEIGHTS.items():
            z = (x - np.log(level * self.tempo)) / sd
            dens = dens + (1.0 - TRACKER_ERROR_RATE) * w * np.exp(-0.5 * z**2) / (sd * np.sqrt(2.0 * np.pi))
        return np.log(dens)

    def refine(self, tempo: float) -> float | None:
        """The sound's own tempo at the metrical level within 4 % of `tempo` (bpm), else None."""
        for level in LEVEL_WEIGHTS:
            if abs(np.log(tempo / (level * self.tempo))) <= np.log1p(_SAME):
                return level * self.tempo
        return None


def sound_beats(track: SoundTrack) -> SoundBeats | None:
    """Track the beats of a sound track.

    Parameters
    ----------
    track : SoundTrack

    Returns
    -------
    SoundBeats or None
        None when there is no steady beat: silence (RMS below
        :data:`SILENCE_RMS`), fewer than :data:`MIN_BEATS` beats on a
        line, a line with more than a fifth of its beats silent
        (:data:`MIN_COVERAGE`), or beats more irregular than
        :data:`MAX_IRREGULARITY`.

    Raises
    ------
    BeatTrackerMissing
        librosa is not installed.
    """
    x = np.asarray(track.samples, dtype=np.float32)
    if x.size == 0 or float(np.sqrt(np.mean(np.square(x, dtype=np.float64)))) < SILENCE_RMS:
        return None
    try:
        import librosa
    except ImportError:
        raise BeatTrackerMissing(
            f"{track.source or 'sound track'}: reading its beat needs librosa: pip install 'capture2notation[audio]'"
        ) from None
    # Silence either side, so that a sound at the first or last sample is an onset too.
    pad = np.zeros(int(round(_PAD_S * track.rate)), dtype=np.float32)
    envelope = librosa.onset.onset_strength(y=np.concatenate([pad, x, pad]), sr=track.rate, hop_length=_HOP)
    bpm, beats = librosa.beat.beat_track(onset_envelope=envelope, sr=track.rate, hop_length=_HOP, units="time")
    beats = np.asarray(beats, dtype=float)
    start = float(np.atleast_1d(bpm)[0])
    if beats.size < MIN_BEATS or not start > 0:
        return None
    period = 60.0 / start
    times = librosa.times_like(envelope, sr=track.rate, hop_length=_HOP) - pad.size / track.rate
    beats = beats - pad.size / track.rate
    snapped, strength = _onset_at_beats(beats, times, envelope, period)
    # A beat stands for an onset: the tracker's beats between onsets (its
    # tempo misread, as on a few sparse clicks) are not evidence.
    found = _line(snapped[strength >= ONSET_FRACTION * envelope.max()], period)
    if found is not None:
        return found
    # Too few tracked beats on onsets: the onsets themselves, numbered from
    # their median spacing.
    peaks = _peaks(envelope, times)
    if peaks.size < MIN_BEATS:
        return None
    return _line(peaks, float(np.median(np.diff(peaks))))


def _peaks(envelope: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Times (s) of the onset envelope's peaks of at least :data:`ONSET_FRACTION` of its largest."""
    from scipy.signal import find_peaks

    hop_s = float(times[1] - times[0]) if times.size > 1 else 1.0
    idx, _ = find_peaks(envelope, height=ONSET_FRACTION * float(envelope.max()), distance=max(1, int(0.1 / hop_s)))
    return times[idx].astype(float)


def _onset_at_beats(beats: np.ndarray, times: np.ndarray, envelope: np.ndarray, period: float):
    """Each tracked beat moved to the strongest onset within ±:data:`_SNAP_PERIODS` of a period.

    The dynamic programme places beats on its own (coarse) tempo's grid, up
    to a few hops off the onsets they stand for; the onsets are the sound's
    own timing (to a fraction of a hop, by a parabola through the peak).

    Returns
    -------
    (B,) ndarray
        The moved beats, seconds.
    (B,) ndarray
        The onset strength there (0 where none is near).
    """
    out = beats.copy()
    strength = np.zeros(beats.size)
    hop_s = float(times[1] - times[0]) if times.size > 1 else 0.0
    for i, b in enumerate(beats):
        near = np.flatnonzero(np.abs(times - b) <= _SNAP_PERIODS * period)
        if near.size == 0:
            continue
        j = int(near[np.argmax(envelope[near])])
        shift = 0.0
        if 0 < j < envelope.size - 1:
            a, c, e = float(envelope[j - 1]), float(envelope[j]), float(envelope[j + 1])
            den = a - 2.0 * c + e
            shift = 0.5 * (a - e) / den if den < 0 else 0.0
        out[i] = float(times[j]) + shift * hop_s
        strength[i] = float(envelope[j])
    return out, strength


def _line(beats: np.ndarray, period: float) -> SoundBeats | None:
    """The tempo of beat times from a line through them, each numbered from `period` (seconds).

    Beats more than :data:`_OUTLIER_PERIODS` off the line (a tracker's beat
    placed between onsets, typically at the ends) are left out and the line
    fitted again.
    """
    keep = np.ones(beats.size, bool)
    k = np.round((beats - beats[0]) / period)
    intercept = float(beats[0])
    for _ in range(3):
        if keep.sum() < MIN_BEATS:
            return None
        design = np.column_stack([k[keep], np.ones(int(keep.sum()))])
        coef, *_ = np.linalg.lstsq(design, beats[keep], rcond=None)
        period, intercept = float(coef[0]), float(coef[1])
        if not period > 0:
            return None
        k = np.round((beats - intercept) / period)
        keep = np.abs(beats - (k * period + intercept)) <= _OUTLIER_PERIODS * period
    kk, resid = k[keep], (beats - (k * period + intercept))[keep]
    if kk.size < MIN_BEATS or np.ptp(kk) < MIN_BEATS - 1:
        return None
    # A steady beat sounds on (nearly) every beat between its first and last.
    if np.unique(kk).size < MIN_COVERAGE * (np.ptp(kk) + 1):
        return None
    irregular = float(np.sqrt(np.mean(resid**2)) / period)
    if irregular > MAX_IRREGULARITY:
        return None
    # Standard error of the slope, relative to the period.
    dof = max(kk.size - 2, 1)
    se = np.sqrt(np.sum(resid**2) / dof / np.sum((kk - kk.mean()) ** 2)) / period
    return SoundBeats(60.0 / period, max(float(se), MIN_RELATIVE_SD), beats[keep], irregular)
