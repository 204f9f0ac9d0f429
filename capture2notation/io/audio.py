"""Sound tracks: a video's audio decoded to mono PCM, WAV files, and audio muxed into an mp4.

Everything goes through the ffmpeg binary that `imageio-ffmpeg` ships (no
system audio libraries): decoding is one ``ffmpeg … -f f32le pipe:1``
subprocess, muxing one ``ffmpeg … -c:v copy -c:a aac`` into a temporary
file renamed over the target (:mod:`capture2notation.atomic`).  WAV files
are read and written with the standard library's :mod:`wave` (16-bit PCM).
"""

from __future__ import annotations

import subprocess
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import AudioError

__all__ = ["AUDIO_RATE", "SoundTrack", "mux_audio", "read_audio", "write_wav"]

#: Sample rate the sound track is decoded at, Hz: librosa's default, ample
#: for beats (onsets are analysed below 11 kHz).
AUDIO_RATE = 22050
#: Largest sound track decoded, seconds (an hour of mono float32 at
#: 22 kHz is 320 MB); longer tracks are cut there, with a warning.
MAX_SECONDS = 3600.0
#: Bit rate of the AAC track muxed into an mp4, bits per second.
_AAC_BITRATE = "128k"


@dataclass(frozen=True, eq=False)
class SoundTrack:
    """Mono audio samples.

    Attributes
    ----------
    samples : (N,) float32 ndarray
        Amplitude in [-1, 1].
    rate : int
        Samples per second, Hz.
    source : str
        The file it came from (for messages).
    """

    samples: np.ndarray
    rate: int
    source: str = ""

    @property
    def seconds(self) -> float:
        """Duration, seconds."""
        return self.samples.size / float(self.rate)


def _ffmpeg() -> str:
    import imageio_ffmpeg

    return imageio_ffmpeg.get_ffmpeg_exe()


def read_audio(path, rate: int = AUDIO_RATE, max_seconds: float = MAX_SECONDS) -> SoundTrack | None:
    """The first audio stream of a video (or audio) file, mixed to mono.

    Parameters
    ----------
    path : str or Path
        Video or audio file ffmpeg can read; an image folder has no sound.
    rate : int
        Sample rate to resample to, Hz.
    max_seconds : float
        Decode at most this many seconds.

    Returns
    -------
    SoundTrack or None
        None when the file has no audio stream (or is a folder).

    Raises
    ------
    AudioError
        Missing file, or ffmpeg cannot decode its audio (the message gives
        ffmpeg's last line).
    """
    path = Path(path)
    if path.is_dir():
        return None
    if not path.is_file():
        raise AudioError(f"{path}: no such file")
    if not (isinstance(rate, int | np.integer) and 1000 <= rate <= 384000):
        raise AudioError(f"{path}: sample rate must be an integer 1000-384000 Hz, got {rate!r}")
    cmd = [_ffmpeg(), "-nostdin", "-v", "error", "-i", str(path), "-map", "0:a:0", "-vn", "-ac", "1"]
    cmd += ["-ar", str(int(rate)), "-t", f"{float(max_seconds):.3f}", "-f", "f32le", "pipe:1"]
    proc = subprocess.run(cmd, capture_output=True, check=False)
    err = proc.stderr.decode("utf-8", "replace").strip()
    if proc.returncode != 0:
        # ffmpeg's way of saying the file has no audio stream.
        if "matches no streams" in err or "does not contain any stream" in err:
            return None
        last = err.splitlines()[-1] if err else f"exit status {proc.returncode}"
        raise AudioError(f"{path}: ffmpeg cannot decode the sound track: {last}")
    samples = np.frombuffer(proc.stdout, dtype="<f4").astype(np.float32)
    if samples.size == 0:
        return None
    return SoundTrack(np.clip(np.nan_to_num(samples), -1.0, 1.0), int(rate), str(path))


def write_wav(path, samples, rate: int) -> Path:
    """Write mono samples in [-1, 1] as a 16-bit PCM WAV file, atomically.

    Parameters
    ----------
    path : str or Path
    samples : (N,) array_like
        Amplitudes; clipped to [-1, 1].
    rate : int
        Samples per second, Hz.

    Returns
    -------
    Path
    """
    path = Path(path)
    x = np.asarray(samples, dtype=float)
    if x.ndim != 1 or x.size == 0 or not np.all(np.isfinite(x)):
        raise AudioError(f"{path}: samples must be a non-empty 1-D array of finite numbers, got shape {x.shape}")
    pcm = np.round(np.clip(x, -1.0, 1.0) * 32767.0).astype("<i2")
    with atomic_path(path, suffix=".wav") as tmp, wave.open(str(tmp), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(int(rate))
        w.writeframes(pcm.tobytes())
    return path


def mux_audio(video, audio, out=None) -> Path:
    """Give an mp4 a sound track: its video stream copied, `audio` encoded as AAC.

    The sound is cut at the end of the video (``-shortest``); a shorter
    sound leaves the rest of the video silent.  Any sound track the video
    had is replaced.

    Parameters
    ----------
    video : str or Path
        The mp4 whose pictures are kept.
    audio : str or Path
        Any audio (or video) file ffmpeg reads; its first audio stream is used.
    out : str or Path, optional
        Output mp4; default: replace `video` (atomically).

    Returns
    -------
    Path
        The written file.
    """
    video, audio = Path(video), Path(audio)
    out = video if out is None else Path(out)
    for p, what in ((video, "video"), (audio, "audio")):
        if not p.is_file():
            raise AudioError(f"{p}: no such {what} file")
    with atomic_path(out, suffix=".mp4") as tmp:
        cmd = [_ffmpeg(), "-nostdin", "-v", "error", "-y", "-i", str(video), "-i", str(audio)]
        cmd += ["-map", "0:v:0", "-map", "1:a:0", "-c:v", "copy", "-c:a", "aac", "-b:a", _AAC_BITRATE]
        cmd += ["-shortest", "-movflags", "+faststart", str(tmp)]
        proc = subprocess.run(cmd, capture_output=True, check=False)
        if proc.returncode != 0:
            err = proc.stderr.decode("utf-8", "replace").strip()
            last = err.splitlines()[-1] if err else f"exit status {proc.returncode}"
            raise AudioError(f"{audio}: cannot mux it into {video}: {last}")
    return out
