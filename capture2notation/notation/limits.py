"""Range guards: what a dance score can hold, as named limits.

Every reader and the model itself check these, so that a malformed or
hostile file fails at once with a one-line error instead of hanging a
parser (``tempo: 1e100000000`` asks :class:`fractions.Fraction` for a
hundred-million-digit integer) or exhausting memory downstream (a tiny
tempo or a start at beat 10⁹ makes the virtual dancer allocate billions of
frames).  The limits are generous for dance and tight for machines:

* tempo within [:data:`MIN_TEMPO`, :data:`MAX_TEMPO`] beats per minute;
* a score at most :data:`MAX_SCORE_SECONDS` long at its tempo, every start
  and duration at most :data:`MAX_BEATS`;
* at most :data:`MAX_SYMBOLS` symbols, :data:`MAX_METER` beats a measure,
  :data:`MAX_TURN` full turns in one turn symbol;
* score files at most :data:`MAX_SCORE_BYTES`, numbers at most
  :data:`MAX_NUMBER_CHARS` characters, titles at most
  :data:`MAX_TITLE_CHARS`.
"""

from __future__ import annotations

from fractions import Fraction

__all__ = [
    "MAX_BEATS",
    "MAX_METER",
    "MAX_NUMBER_CHARS",
    "MAX_SCORE_BYTES",
    "MAX_SCORE_SECONDS",
    "MAX_SYMBOLS",
    "MAX_TEMPO",
    "MAX_TITLE_CHARS",
    "MAX_TURN",
    "MIN_TEMPO",
]

#: Slowest tempo, beats per minute: a beat of 6 s, slower than any pulse a
#: dancer counts (the sad preset is 37 bpm).
MIN_TEMPO = Fraction(10)
#: Fastest tempo, beats per minute: 6.7 beats a second, beyond the fastest
#: dance music (footwork styles reach about 300 bpm).
MAX_TEMPO = Fraction(400)
#: Longest score, seconds at its tempo: an hour, longer than any phrase or
#: act notated in one score, and about 90,000 frames at 25 fps for the
#: virtual dancer.
MAX_SCORE_SECONDS = 3600
#: Largest start or duration of a symbol, beats: an hour at the fastest tempo.
MAX_BEATS = Fraction(MAX_SCORE_SECONDS) * MAX_TEMPO / 60
#: Most symbols in one score: every part changing on every beat for a
#: quarter of an hour at 60 bpm; about 40 MB in memory.
MAX_SYMBOLS = 50_000
#: Most beats in one measure (the staff draws a tick on every beat).
MAX_METER = 64
#: Most full turns written in one turn symbol (pirouette records are near 20).
MAX_TURN = Fraction(32)
#: Largest score file, bytes: a .lab of MAX_SYMBOLS lines is about 3 MB, its
#: indented JSON about 8 MB.
MAX_SCORE_BYTES = 16 * 2**20
#: Longest number token (start, duration, tempo, amount, milliseconds).
MAX_NUMBER_CHARS = 40
#: Longest title, characters.
MAX_TITLE_CHARS = 1000
