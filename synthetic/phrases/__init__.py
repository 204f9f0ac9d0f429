"""Built-in phrases of the virtual dancer, stored as ``.lab`` score files.

* ``figure7`` — Wolofsky's (1974) Figure 7 phrase: a left-leg gesture over
  a right-foot support (DESIGN.md).
* ``port_de_bras`` — Cecchetti's third port de bras (Neagle 2005 §3.2.2),
  rounded arms (bend 1), tempo 64 and the happy Effort of Neagle's Table 5.1.
* ``leg_phrase`` — plié, rise and relevé on both feet, a weight transfer, free
  leg gestures (bent and straight), a closing and a step forward.
* ``turn_and_jump`` — a sauté (jump) from a plié, a slow quarter turn on both
  feet, a half pirouette in relevé, a closing and a step: the fidelity
  study's turning and jumping phrase.

The files are read through the one front door
:func:`capture2notation.notation.read`, so they double as format examples.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from capture2notation.notation import Score, read

__all__ = ["PHRASE_NAMES", "builtin_phrases", "phrase", "phrase_path"]

#: Names of the built-in phrases (file stems).
PHRASE_NAMES: tuple[str, ...] = ("figure7", "port_de_bras", "leg_phrase", "turn_and_jump")


def phrase_path(name: str) -> Path:
    """Path of a built-in phrase's ``.lab`` file."""
    from capture2notation.errors import SyntheticError

    if name not in PHRASE_NAMES:
        raise SyntheticError(f"unknown built-in phrase {name!r}; expected one of {', '.join(PHRASE_NAMES)}")
    return Path(str(resources.files(__name__).joinpath(f"{name}.lab")))


def phrase(name: str) -> Score:
    """One built-in phrase as a :class:`Score`."""
    return read(phrase_path(name))


def builtin_phrases() -> dict[str, Score]:
    """All built-in phrases, ``{name: Score}`` in :data:`PHRASE_NAMES` order."""
    return {name: phrase(name) for name in PHRASE_NAMES}
