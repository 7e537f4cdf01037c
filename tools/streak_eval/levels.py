"""Light levels and road shapes of the outside streets (no bpy), for blender_streets.py.

Light levels follow docs/decisions/0030; Blender's glTF exporter writes a point or spot lamp
of P watts as P / (4 pi) * 683 cd times its colour, and emission strength as radiance.
"""

from __future__ import annotations

import math


def luminance(rgb: tuple[float, float, float]) -> float:
    """The relative luminance of a linear sRGB colour."""
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


def watts_for_candela(candela: float, colour: tuple[float, float, float]) -> float:
    """Blender's Power of a point or spot lamp of `colour` whose luminous intensity is
    `candela` (the exporter writes P / (4 pi) * 683 cd, times the colour)."""
    return 4.0 * math.pi * candela / (683.0 * luminance(colour))


def radiance_for_luminance(cd_m2: float, colour: tuple[float, float, float]) -> float:
    """Emission Strength of an emitter of `colour` whose luminance is `cd_m2`."""
    return cd_m2 / (683.0 * luminance(colour))


def smoothstep(t: float) -> float:
    """3 t^2 - 2 t^3 on t clamped to [0, 1]."""
    t = min(1.0, max(0.0, t))
    return t * t * (3.0 - 2.0 * t)


def hill_profile(s: float) -> float:
    """The centre line's height: level at the camera, climbing 2.5 m over s = 5..60 m (grade
    up to 6.8 %), a crest, then falling 3 m over s = 70..120 m."""
    return 2.5 * smoothstep((s - 5.0) / 55.0) - 3.0 * smoothstep((s - 70.0) / 50.0)


def crown(x: float, half: float, rise: float) -> float:
    """A crowned carriageway's height: `rise` on the centre line, 0 at +-`half`."""
    return rise * max(0.0, 1.0 - (x / half) ** 2)


def eased_grade(y: float, grade: float, ease_from: float, ease_len: float) -> float:
    """A road's height along y: a constant `grade` (rise / run, e.g. -0.04) from y = 0 up to
    `ease_from`, easing to level over the next `ease_len` metres (the grade times 1 -
    smoothstep), level after; 0 at y = 0 and continuous in height and grade."""
    if y <= ease_from:
        return grade * y
    t = min(1.0, (y - ease_from) / ease_len)
    return grade * (ease_from + ease_len * (t - t**3 + 0.5 * t**4))


def watts_for_lux(lux: float, colour: tuple[float, float, float]) -> float:
    """Blender's Strength (W/m^2) of a sun lamp of `colour` whose illuminance is `lux` (the
    exporter writes the strength times 683 as lux, times the colour)."""
    return lux / (683.0 * luminance(colour))


def ramp_grade(s: float, g0: float, g1: float, length: float) -> float:
    """A road's height along s whose grade rises smoothly (smoothstep) from `g0` at s = 0 to
    `g1` at s = `length` and stays there; `g0` before s = 0. 0 at s = 0, continuous in height
    and grade (the smoothstep's integral is length (t^3 - t^4 / 2))."""
    if s <= 0.0:
        return g0 * s
    t = min(1.0, s / length)
    return g0 * s + (g1 - g0) * (length * (t**3 - 0.5 * t**4) + max(0.0, s - length))
