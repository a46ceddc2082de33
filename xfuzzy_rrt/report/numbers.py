"""Numbers as a person reads them: 3-4 significant digits with units.

Why a module of its own: the report, ``rules show``, ``explain`` and the ``rules eval`` echo all
print numbers for people, and ``goal_bias = 2.4664367420312074e-05`` or ``0.44999999999999996
m`` tells a reader nothing the fourth digit did not. Files (rulebooks, CSV, JSON) keep full
precision; only what is *shown* goes through here. Every function returns a string and renders
NaN/None as an em dash, so a missing value is visible rather than a crash.
"""

from __future__ import annotations

import math
import re
from typing import Any

DASH = "\u2014"
#: Significant digits shown by default.
DIGITS = 4


def _float(value: Any) -> float | None:
    if value is None or isinstance(value, bool):
        return None
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(x) else x


def sig(value: Any, digits: int = DIGITS) -> str:
    """``value`` with ``digits`` significant digits, no exponent between 1e-4 and 1e6,
    trailing zeros dropped (``sig(0.44999999999999996) == '0.45'``, ``sig(1234.5) == '1235'``,
    ``sig(2.4664367420312074e-05) == '2.466e-05'``)."""
    x = _float(value)
    if x is None:
        return DASH
    if math.isinf(x):
        return "\u221e" if x > 0 else "-\u221e"
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if -4 <= mag < 6:
        decimals = max(0, digits - 1 - mag)
        text = f"{x:.{decimals}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text
    mant, exp = f"{x:.{digits - 1}e}".split("e")
    if "." in mant:
        mant = mant.rstrip("0").rstrip(".")
    return f"{mant}e{exp}"


def qty(value: Any, unit: str = "", digits: int = DIGITS) -> str:
    """``sig(value)`` followed by its unit (``'0.45 m'``, ``'12.5°'`` for degrees)."""
    text = sig(value, digits)
    if text == DASH or not unit:
        return text
    if unit in ("deg", "\u00b0"):
        return f"{text}\u00b0"
    return f"{text} {unit}"


def seconds(value: Any, digits: int = 3) -> str:
    """A duration in the unit that reads best: ``'850 µs'``, ``'12.3 ms'``, ``'1.24 s'``."""
    x = _float(value)
    if x is None:
        return DASH
    a = abs(x)
    if a == 0:
        return "0 s"
    if a < 1e-3:
        return f"{sig(x * 1e6, digits)} \u00b5s"
    if a < 1:
        return f"{sig(x * 1e3, digits)} ms"
    return f"{sig(x, digits)} s"


def metres(value: Any, digits: int = 3) -> str:
    """A length in m, mm or µm (clearances and penetrations are millimetres)."""
    x = _float(value)
    if x is None:
        return DASH
    a = abs(x)
    if a == 0:
        return "0 mm"
    if a < 1e-3:
        return f"{sig(x * 1e6, digits)} \u00b5m"
    if a < 1:
        return f"{sig(x * 1e3, digits)} mm"
    return f"{sig(x, digits)} m"


def percent(value: Any) -> str:
    """A fraction as a whole percent (``0.9583 -> '96%'``); 99.5 % and up never rounds to
    100 % unless it is 1 (a reader must not see 100 % for 199/200)."""
    x = _float(value)
    if x is None:
        return DASH
    p = 100 * x
    if p < 100 and round(p) == 100:
        return f"{p:.1f}%" if p < 99.95 else "99.9%"
    if 0 < p and round(p) == 0:
        return "<1%"
    return f"{p:.0f}%"


def ratio(value: Any) -> str:
    """A speed-up ratio: ``'1.4×'`` (two significant digits are what a ratio can carry)."""
    x = _float(value)
    if x is None:
        return DASH
    return f"{sig(x, 2 if 0.1 <= abs(x) < 100 else 3)}\u00d7"


def unit_of(unit: str) -> str:
    """How a rulebook unit reads after a number (``'rad'``, ``'m'``, ``'°'``, ``''``)."""
    return "\u00b0" if unit == "deg" else unit


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def readable_numbers(text: str, digits: int = DIGITS) -> str:
    """Every decimal number in ``text`` rewritten with :func:`sig` (rule sentences, provenance
    values); integers without a fraction or exponent (rule and term indices) stay as they are."""

    def repl(m: re.Match) -> str:
        s = m.group(0)
        if re.fullmatch(r"[-+]?\d+", s):
            return s
        return sig(float(s), digits)

    return _NUMBER.sub(repl, text)
