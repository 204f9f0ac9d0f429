"""Fronts, turns and spring forms derived from a score (notation.facing)."""

from __future__ import annotations

from fractions import Fraction

import pytest

from capture2notation.notation.facing import (
    feet_before,
    front_at,
    front_changes,
    room_direction,
    spring_form,
    springs,
)
from capture2notation.notation.formats import lab


def _score(body: str):
    return lab.loads("tempo: 60\n" + body)


@pytest.mark.parametrize(
    "before,landing,form",
    [
        ("0 1 support place low", "3/2 1/2 support place low", "jump"),
        ("0 1 right_support place low\n0 1 left_leg forward low", "3/2 1/2 right_support place low", "hop"),
        ("0 1 right_support place low\n0 1 left_leg forward low", "3/2 1/2 left_support forward low", "leap"),
        ("0 1 left_support place low\n0 1 right_leg back low", "3/2 1/2 support place low", "assemblé"),
        ("0 1 support place low", "3/2 1/2 right_support place low", "sissonne"),
    ],
)
def test_the_five_spring_forms(before, landing, form):
    score = _score(f"{before}\n1 1/2 support air\n{landing}\n")
    ((air, got),) = springs(score)
    assert air.is_air and got == form == spring_form(score, air)


def test_a_gesture_lifts_the_foot_and_a_flight_needs_a_landing():
    # After both feet, the left leg gestures: the take-off is from the right foot only.
    score = _score("0 1 support place low\n1 1 left_leg forward low\n2 1/2 support air\n5/2 1 right_support place low")
    assert feet_before(score, 2) == {"right"}
    assert springs(score)[0][1] == "hop"
    # The start pose stands on both feet; no landing: no form.
    score = _score("0 1/2 support air\n")
    assert feet_before(score, 0) == {"right", "left"} and springs(score)[0][1] is None


def test_fronts_add_up_unwrapped():
    score = _score(
        "0 1 turn right amount=1\n1 1 turn right amount=1\n2 2 turn left amount=3/8\n4 1 head forward high\n"
    )
    assert [f for _, f in front_changes(score)] == [1, 2, Fraction(13, 8)]
    assert front_at(score, 0) == 0 and front_at(score, Fraction(1, 2)) == Fraction(1, 2)
    assert front_at(score, 3) == 2 - Fraction(3, 16) and front_at(score, 10) == Fraction(13, 8)
    assert room_direction(Fraction(13, 8)) == "left_back"
    assert [room_direction(Fraction(k, 8)) for k in range(-2, 3)] == [
        "left",
        "left_forward",
        "forward",
        "right_forward",
        "right",
    ]
