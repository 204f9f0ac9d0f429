"""Sound tracks: decoding a file's audio, WAV files, muxing audio into an mp4."""

from __future__ import annotations

import numpy as np
import pytest

from capture2notation.errors import AudioError
from capture2notation.io.audio import SoundTrack, mux_audio, read_audio, write_wav
from capture2notation.io.video import VideoWriter, probe


def _tone(seconds=1.0, rate=22050, hz=440.0, amp=0.5):
    t = np.arange(int(seconds * rate)) / rate
    return (amp * np.sin(2 * np.pi * hz * t)).astype(np.float32)


def _video(path, frames=25, fps=25.0):
    with VideoWriter(path, fps, (64, 48)) as w:
        for i in range(frames):
            w.write(np.full((48, 64, 3), 10 * (i % 20), np.uint8))
    return path


def test_wav_round_trip_keeps_samples_to_16_bits(tmp_path):
    x = _tone()
    track = read_audio(write_wav(tmp_path / "a.wav", x, 22050))
    assert isinstance(track, SoundTrack) and track.rate == 22050
    assert track.samples.shape == x.shape and track.seconds == pytest.approx(1.0)
    # 16-bit PCM: within one quantisation step (1/32767) plus float32 rounding.
    assert np.max(np.abs(track.samples - x)) <= 1.5 / 32767


def test_resampling_keeps_duration_and_pitch(tmp_path):
    track = read_audio(write_wav(tmp_path / "a.wav", _tone(2.0, rate=44100, hz=500.0), 44100), rate=8000)
    assert track.rate == 8000 and track.seconds == pytest.approx(2.0, abs=0.01)
    spectrum = np.abs(np.fft.rfft(track.samples))
    assert np.fft.rfftfreq(track.samples.size, 1 / 8000)[np.argmax(spectrum)] == pytest.approx(500.0, abs=1.0)


def test_a_silent_video_or_folder_has_no_sound_track(tmp_path):
    assert read_audio(_video(tmp_path / "v.mp4")) is None
    (tmp_path / "frames").mkdir()
    assert read_audio(tmp_path / "frames") is None


def test_muxed_sound_is_cut_at_the_end_of_the_video(tmp_path):
    video = _video(tmp_path / "v.mp4", frames=25)  # one second
    wav = write_wav(tmp_path / "a.wav", _tone(3.0), 22050)
    assert mux_audio(video, wav) == video
    info = probe(video)
    assert info.frame_count == 25 and info.image_size == (64, 48)  # pictures copied
    track = read_audio(video)
    assert track is not None and track.seconds == pytest.approx(1.0, abs=0.1)
    assert 0.2 < np.sqrt(np.mean(track.samples**2)) < 0.5  # the tone (RMS 0.35), not silence
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_bad_audio_input_is_named(tmp_path):
    with pytest.raises(AudioError, match=r"missing\.mp4: no such file"):
        read_audio(tmp_path / "missing.mp4")
    junk = tmp_path / "junk.mp4"
    junk.write_bytes(b"not a video at all")
    with pytest.raises(AudioError, match=r"junk\.mp4: ffmpeg cannot decode"):
        read_audio(junk)
    with pytest.raises(AudioError, match="1-D array of finite"):
        write_wav(tmp_path / "b.wav", [np.nan], 22050)
    with pytest.raises(AudioError, match="no such audio file"):
        mux_audio(_video(tmp_path / "v.mp4"), tmp_path / "none.wav")
    with pytest.raises(AudioError, match="cannot mux"):
        mux_audio(_video(tmp_path / "w.mp4"), junk)
