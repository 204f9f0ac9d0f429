"""Sound for a render: a click track at the score's tempo, or a user's music, muxed into the mp4.

``c2n render --audio click`` gives ``video.mp4`` a metronome: a click on
every beat from beat 0 at time 0 (the score's and the render's first
frame), the first beat of each measure higher and louder, so a beat
tracker finds the written tempo and a listener the meter.
``--audio FILE`` muxes FILE's sound instead (cut at the end of the video).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from capture2notation.errors import SyntheticError
from capture2notation.io.audio import AUDIO_RATE, mux_audio, write_wav

__all__ = ["CLICK", "add_sound", "click_track"]

#: The `audio` value for a click track.
CLICK = "click"
#: Pitch of a click, Hz: an ordinary beat and the first beat of a measure
#: (a metronome's two woodblock-like tones).
CLICK_HZ = (1000.0, 1600.0)
#: Peak amplitude of an ordinary and of an accented click (full scale 1).
CLICK_AMPLITUDE = (0.5, 0.9)
#: Length of a click, seconds, and the time constant of its decay.
CLICK_SECONDS = 0.05
CLICK_DECAY_S = 0.01


def click_track(tempo, meter: int, seconds: float, rate: int = AUDIO_RATE) -> np.ndarray:
    """A metronome: a click on every beat, accented on the first beat of each measure.

    Parameters
    ----------
    tempo : number
        Beats per minute (> 0).
    meter : int
        Beats per measure (>= 1): beats 0, meter, 2·meter … are accented.
    seconds : float
        Length of the track, seconds (> 0).
    rate : int
        Samples per second, Hz.

    Returns
    -------
    (N,) float32 ndarray
        ``N = round(seconds · rate)`` samples in [-1, 1].
    """
    bpm = float(tempo)
    if not (np.isfinite(bpm) and bpm > 0):
        raise SyntheticError(f"click track: tempo must be > 0 beats per minute, got {tempo!r}")
    if int(meter) < 1:
        raise SyntheticError(f"click track: meter must be >= 1 beats per measure, got {meter!r}")
    if not (np.isfinite(seconds) and seconds > 0):
        raise SyntheticError(f"click track: length must be > 0 seconds, got {seconds!r}")
    n = int(round(seconds * rate))
    out = np.zeros(n, dtype=np.float64)
    t = np.arange(int(round(CLICK_SECONDS * rate))) / rate
    shape = np.exp(-t / CLICK_DECAY_S)
    clicks = [a * shape * np.sin(2 * np.pi * hz * t) for hz, a in zip(CLICK_HZ, CLICK_AMPLITUDE)]
    spb = 60.0 / bpm
    for k in range(int(np.floor(seconds / spb)) + 1):
        start = int(round(k * spb * rate))
        if start >= n:
            break
        click = clicks[1] if k % int(meter) == 0 else clicks[0]
        m = min(click.size, n - start)
        out[start : start + m] += click[:m]
    return np.clip(out, -1.0, 1.0).astype(np.float32)


def add_sound(video, audio: str, tempo, meter: int, seconds: float) -> Path:
    """Mux a click track (`audio` ``"click"``) or the sound of the file `audio` into the mp4 `video`.

    Parameters
    ----------
    video : str or Path
        A rendered ``.mp4`` (replaced atomically).
    audio : str
        ``"click"``, or a path to any audio or video file ffmpeg reads.
    tempo : number
        Beats per minute of the click track.
    meter : int
        Beats per measure (the click track's accents).
    seconds : float
        Length of the video, seconds.

    Returns
    -------
    Path
        The video.
    """
    video = Path(video)
    if video.suffix.lower() != ".mp4":
        raise SyntheticError(f"{video}: a sound track needs an mp4 video (not a folder of PNG frames)")
    if audio != CLICK:
        source = Path(audio)
        if not source.is_file():
            raise SyntheticError(f"--audio {audio!r}: no such file; expected 'click' or a music file")
        return mux_audio(video, source)
    with tempfile.TemporaryDirectory(dir=video.parent) as tmp:
        wav = write_wav(Path(tmp) / "click.wav", click_track(tempo, meter, seconds), AUDIO_RATE)
        return mux_audio(video, wav)
